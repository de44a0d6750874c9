"""Fixtures of the integration tests; the harness itself is in harness.py."""

import pytest
from harness import Launcher, Observer, private_domain


@pytest.fixture
def domain():
    with private_domain() as domain:
        yield domain


@pytest.fixture
def launcher(domain, tmp_path):
    launcher = Launcher(domain, tmp_path)
    try:
        yield launcher
    finally:
        launcher.stop()


@pytest.fixture
def observer(domain):
    observer = Observer(domain)
    try:
        yield observer
    finally:
        observer.close()
