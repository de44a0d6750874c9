"""Where the tests find the repository's files, wherever a test file sits in the tree."""

from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SCENARIOS = REPO / 'config' / 'scenarios'
PAPER = SCENARIOS / 'solar_panel.yaml'
FRAGMENTS = REPO / 'config' / 'fragments'
DATA = Path(__file__).resolve().parent / 'data'
