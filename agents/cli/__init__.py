"""The ``digslam`` command line: the only place that wires argparse.

Lives here: :mod:`.main` (the parser and the subcommands: demo, train, evaluate, record, replay, sweep,
warmup...) and :mod:`.warmup` (compiling every kernel once).

May import: everything in :mod:`digslam`.
"""

from .main import main

__all__ = ["main"]
