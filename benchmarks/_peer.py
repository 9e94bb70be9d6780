"""Run the codac peer (benchmarks/codac_peer.py) in a subprocess and read its JSON answer."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

PEER = Path(__file__).with_name("codac_peer.py")


def codac(*args: object, timeout: float = 600) -> dict:
    """Answer of ``codac_peer.py ARGS``; raises with codac's stderr when it fails."""
    res = subprocess.run(
        [sys.executable, str(PEER), *map(str, args)], capture_output=True, text=True, timeout=timeout
    )
    if res.returncode != 0:
        raise RuntimeError(f"codac peer {args} failed (is codac installed? pip install codac):\n{res.stderr}")
    return json.loads(res.stdout.strip().splitlines()[-1])
