"""The ``digslam`` command line: the only place that wires argparse.

Lives here: :mod:`.main` (the entry point :func:`~.main.main`, re-exporting the public names below),
:mod:`.parser` (the parser), :mod:`.common` (``UserError``, path and environment checks, staged writes),
:mod:`.agents` (``--agent`` names and saved models), :mod:`.commands` (demo, train, evaluate, warmup,
benchmark), :mod:`.episodes` (record, replay), :mod:`.distributed` (``evaluate --ray``, sweep) and
:mod:`.warmup` (compiling every kernel once).

May import: everything in :mod:`digslam`. Nothing outside this folder imports it.

The console script ``digslam`` is ``digslam.agents.cli.main:main``.
"""
