"""A real headless browser for the tests and the bench: Debian's Chromium, driven by Selenium
through Debian's chromedriver (no browser or driver is downloaded).

The flags keep Chromium from reaching for the network: on a machine without internet its
background services (updates, sync, QUIC probes) otherwise stall page loads.
"""

import shutil
import socket
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

CHROMIUM = ('/usr/bin/chromium', '/usr/bin/chromium-browser')
CHROMEDRIVER = '/usr/bin/chromedriver'
FLAGS = ('--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync',
         '--disable-dev-shm-usage')


def find_chromium() -> tuple[str, str] | None:
    """(browser, driver) paths, or None if either is missing."""
    browser = next((path for path in CHROMIUM if Path(path).is_file()), None)
    driver = CHROMEDRIVER if Path(CHROMEDRIVER).is_file() else shutil.which('chromedriver')
    return (browser, driver) if browser and driver else None


@contextmanager
def headless_browser(width: int = 1400, height: int = 1000):
    """A Selenium WebDriver on a fresh headless Chromium profile; quit on exit."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    found = find_chromium()
    if found is None:
        raise FileNotFoundError('Chromium or chromedriver not found (on Debian: apt-get install '
                                'chromium chromium-driver)')
    browser, driver_path = found
    profile = tempfile.mkdtemp(prefix='fjsp-chromium-')
    options = webdriver.ChromeOptions()
    options.binary_location = browser
    options.set_capability('goog:loggingPrefs', {'browser': 'ALL'})
    for flag in (*FLAGS, f'--user-data-dir={profile}', f'--window-size={width},{height}'):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(driver_path), options=options)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


def free_port() -> int:
    """A TCP port on 127.0.0.1 nothing listens on now (for a monitor's live page)."""
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


def wait_listening(port: int, timeout: float) -> bool:
    """Whether something serves `port` on 127.0.0.1 within `timeout` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            socket.create_connection(('127.0.0.1', port), timeout=1).close()
            return True
        except OSError:
            if time.monotonic() > deadline:
                return False
            time.sleep(0.2)
