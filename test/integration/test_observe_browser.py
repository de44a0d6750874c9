"""The live mission page in a real headless browser (Debian's Chromium through Selenium): a
fleet runs, a robot fails mid-mission, and the page shows what a person watching it must see;
the robots move on the map of a scenario that has one, and the page draws the mission on
first load, before its event stream says anything.
"""

import pytest

from fjsp_msgs.msg import MissionStatus

from browser import find_chromium, free_port, headless_browser, wait_listening
from repo_paths import PAPER, SCENARIOS

ROBOTS = ('Assembler', 'LSMS', 'MARC1', 'MARC2')

if find_chromium() is None:
    pytest.skip('Chromium and chromedriver not found (on Debian: apt-get install chromium '
                'chromium-driver); the live page cannot be tested in a browser',
                allow_module_level=True)

from selenium.common.exceptions import TimeoutException  # noqa: E402
from selenium.webdriver.support.ui import WebDriverWait  # noqa: E402

SLOW = 0.3
"""Wall seconds per schedule unit: the failure at schedule time 8 leaves the page about 7 s
of mission to follow, time for a loaded machine to read it."""


# The page redraws its parts as updates come, so it is read in one script call each time
# (an element found a moment ago may already have been replaced).

def text(page, selector: str) -> str:
    return page.execute_script(
        'const e = document.querySelector(arguments[0]); return e ? e.textContent : ""',
        selector)


def attributes(page, selector: str, name: str) -> list[str]:
    return page.execute_script(
        'return [...document.querySelectorAll(arguments[0])]'
        '.map(e => e.getAttribute(arguments[1]))', selector, name)


def wait_page(page, condition, timeout, what):
    try:
        WebDriverWait(page, timeout, poll_frequency=0.2).until(lambda p: condition(p))
    except TimeoutException:
        pytest.fail(f'the page did not show {what} within {timeout:g} s; it shows:\n'
                    + page.execute_script('return document.body.innerText'))


def story(page) -> list[str]:
    return page.execute_script(
        'return [...document.querySelectorAll("#story li")].map(e => e.textContent)')


def test_live_page_follows_a_mission_through_a_failure(fjsp_fleet, tmp_path):
    port = free_port()
    fleet = fjsp_fleet(PAPER, time_scale=SLOW)
    fleet.start_monitor(out_dir=tmp_path, web_port=port)
    fleet.start_planner()
    for robot in ROBOTS:
        fleet.start_agent(robot)
    assert wait_listening(port, 30), f'the monitor did not serve its page on port {port}'
    with headless_browser() as page:
        page.get(f'http://127.0.0.1:{port}/')
        wait_page(page, lambda p: text(p, '#state') == 'executing', 60, 'the mission executing')
        assert attributes(page, '#connection', 'data-state') == ['live']
        assert text(page, '#revision') == '1'
        assert set(attributes(page, '#robots tbody tr', 'data-robot')) == {
            robot for robot in ROBOTS}

        fleet.wait_for(lambda o: o.status and o.status.elapsed >= 8, 60, 'schedule time 8')
        fleet.inject_fault('MARC1', 'fail')
        wait_page(page, lambda p: text(p, '#robots tr[data-robot="MARC1"] td.mode') == 'failed',
                  20, 'MARC1 failed in the robots table')
        wait_page(page, lambda p: int(text(p, '#revision') or 0) >= 2, 30, 'revision 2')
        # Back at once, while the mission still runs however slowly the page is read.
        fleet.inject_fault('MARC1', 'recover')
        wait_page(page, lambda p: any('revision 2 planned' in line for line in story(p)), 10,
                  'the re-plan in the events')
        assert any(line.endswith('MARC1 failed') for line in story(page)), story(page)
        assert attributes(page, '#timeline rect.health.failed', 'class')
        assert len(attributes(page, '#timeline line.revision', 'class')) >= 2

        fleet.wait_for(lambda o: o.status.state == MissionStatus.STATE_COMPLETE, 90,
                          'the mission to complete')
        wait_page(page, lambda p: text(p, '#state') == 'complete' and text(p, '#jobs') == '12/12',
                  20, 'the mission complete, 12/12')
        assert any('MARC1 back in service' in line for line in story(page)), story(page)
        assert any('mission complete: 12/12 jobs done' in line for line in story(page))
        assert len(set(attributes(page, '#timeline rect.work.done', 'data-job'))) == 12
        errors = [e for e in page.get_log('browser') if e['level'] == 'SEVERE']
        assert not errors, errors


def robot_marks(page) -> dict[str, tuple[float, float]]:
    """Each robot on the map: where the page draws it."""
    return page.execute_script(
        'return Object.fromEntries([...document.querySelectorAll("#map circle.robot")]'
        '.map(e => [e.dataset.robot, [+e.getAttribute("cx"), +e.getAttribute("cy")]]))')


def test_the_map_shows_the_robots_moving_and_the_page_draws_on_first_load(fjsp_fleet,
                                                                          tmp_path):
    port = free_port()
    fleet = fjsp_fleet(SCENARIOS / 'yard.yaml', time_scale=0.5)
    robots = {r.name for r in fleet.problem.robots}
    fleet.start_monitor(out_dir=tmp_path, web_port=port)
    assert wait_listening(port, 30), f'the monitor did not serve its page on port {port}'
    fleet.start()
    with headless_browser() as page:
        page.get(f'http://127.0.0.1:{port}/')
        wait_page(page, lambda p: set(robot_marks(p)) == robots, 60, 'every robot on the map')
        assert set(attributes(page, '#map circle.place', 'data-place')) == {
            'depot', 'gate', 'mount', 'mast_head', 'pad'}
        seen = {robot: {tuple(xy)} for robot, xy in robot_marks(page).items()}

        def moved(p) -> bool:
            for robot, xy in robot_marks(p).items():
                seen[robot].add(tuple(xy))
            return sum(len(spots) > 2 for spots in seen.values()) >= 2
        # A robot on a leg is drawn along it, not only at its ends.
        wait_page(page, moved, 30, 'two robots moving along their legs')

        # A page whose event stream never answers still shows the mission, its robots on
        # the map and its timeline: all of it came with the page.
        page.execute_cdp_cmd('Network.enable', {})
        page.execute_cdp_cmd('Network.setBlockedURLs', {'urls': ['*/events']})
        page.get(f'http://127.0.0.1:{port}/')
        fleet.wait_for(lambda o: o.plans, 30, 'the plan')
        assert text(page, '#mission-id') == fleet.observer.plans[0].mission_id
        # (On a loaded machine the mission may have ended meanwhile.)
        assert text(page, '#state') in ('executing', 'complete')
        assert set(robot_marks(page)) == robots
        assert attributes(page, '#timeline rect.plan-first', 'class')
        assert attributes(page, '#connection', 'data-state') != ['live']
        page.execute_cdp_cmd('Network.setBlockedURLs', {'urls': []})
        fleet.check_mission_complete(timeout=90)
