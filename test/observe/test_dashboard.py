"""The live page's server (no ROS): the page and its files, the data as JSON, and updates
streamed as server-sent events, only the parts that changed. The page in a real browser over
a real fleet is test/integration/test_observe_browser.py."""

import http.client
import json

import pytest

from fjsp_planner.observe.dashboard import Dashboard


@pytest.fixture
def dashboard():
    server = Dashboard('127.0.0.1', 0)
    try:
        yield server
    finally:
        server.close()


def get(server: Dashboard, path: str):
    host, port = server.url.split('//')[1].rstrip('/').split(':')
    connection = http.client.HTTPConnection(host, int(port), timeout=10)
    connection.request('GET', path)
    return connection, connection.getresponse()


def test_the_page_and_its_files_are_served_from_the_package(dashboard):
    _, page = get(dashboard, '/')
    html = page.read().decode()
    assert page.status == 200 and 'text/html' in page.getheader('Content-Type')
    assert 'dashboard.js' in html and 'dashboard.css' in html
    assert 'http' not in html.replace('http://www.w3.org', '')  # nothing fetched from elsewhere
    for path, kind in (('/dashboard.js', 'javascript'), ('/dashboard.css', 'css')):
        _, response = get(dashboard, path)
        assert response.status == 200 and kind in response.getheader('Content-Type')
        assert response.read()
    _, missing = get(dashboard, '/secret')
    assert missing.status == 404


def test_the_data_is_there_as_json(dashboard):
    dashboard.publish({'mission': {'state': 'executing'}, 'robots': []})
    _, response = get(dashboard, '/state')
    assert json.loads(response.read()) == {'mission': {'state': 'executing'}, 'robots': []}


def test_a_plain_get_of_the_page_holds_the_mission(dashboard):
    """What curl, a browser without JavaScript or a screenshot on load gets: the mission,
    not an empty page waiting for its event stream."""
    dashboard.publish({'mission': {'mission_id': 'yard-1', 'scenario': 'yard',
                                   'state': 'executing', 'revision': 1, 'jobs_done': 2,
                                   'jobs_total': 9},
                       'robots': [{'robot': 'Truck1', 'type': 'Truck', 'mode': 'travelling',
                                   'location': 'depot', 'destination': 'mount',
                                   'progress': 0.5}]})
    _, page = get(dashboard, '/')
    html = page.read().decode()
    assert '<span id="mission-id">yard-1</span>' in html
    assert '<span id="jobs">2/9</span>' in html
    assert '<tr data-robot="Truck1">' in html and 'depot \u2192 mount' in html


def read_event(response) -> dict:
    lines = []
    while True:
        line = response.fp.readline().decode()
        if line == '\n' and lines:
            break
        if line.startswith('data: '):
            lines.append(line[len('data: '):])
    return json.loads(''.join(lines))


def test_updates_stream_only_what_changed(dashboard):
    assert dashboard.publish({'mission': {'state': 'executing'}, 'robots': [1]}) == \
        ['mission', 'robots']
    connection, stream = get(dashboard, '/events')
    assert stream.getheader('Content-Type') == 'text/event-stream'
    assert read_event(stream) == {'mission': {'state': 'executing'}, 'robots': [1]}
    assert dashboard.publish({'mission': {'state': 'executing'}, 'robots': [1, 2]}) == \
        ['robots']
    assert read_event(stream) == {'robots': [1, 2]}
    assert dashboard.publish({'mission': {'state': 'executing'}}) == []
    dashboard.publish({'mission': {'state': 'complete'}})
    assert read_event(stream) == {'mission': {'state': 'complete'}}
    connection.close()


def test_a_port_in_use_is_refused_at_once(dashboard):
    port = int(dashboard.url.rstrip('/').rsplit(':', 1)[1])
    with pytest.raises(OSError):
        Dashboard('127.0.0.1', port)
