"""The live page as the server sends it (no ROS, no browser): the mission written into the
HTML, so a plain GET shows it, and every part embedded for the script to draw at once."""

import json
import re
from html.parser import HTMLParser

from fjsp_planner.observe import views
from fjsp_planner.observe.dashboard import PAGE
from fjsp_planner.observe.history import FleetHistory
from fjsp_planner.observe.page import render

from mission_facts import MISSION, at, faulty_mission


class Text(HTMLParser):
    """The text of each element with an id, and the embedded JSON."""

    def __init__(self):
        super().__init__()
        self.by_id, self.open, self.rows = {}, [], []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.open.append(attrs.get('id'))
        if tag == 'tr' and 'data-robot' in attrs:
            self.rows.append(attrs['data-robot'])

    def handle_endtag(self, tag):
        if self.open:
            self.open.pop()

    def handle_data(self, data):
        for name in self.open:
            if name:
                self.by_id[name] = self.by_id.get(name, '') + data


def parts_of(facts, wall) -> dict:
    fleet = FleetHistory()
    for fact in facts:
        fleet.add(fact)
    mission = fleet.missions[MISSION]
    header = views.header(mission, wall)
    header['planner'] = ''
    return {'mission': header, 'robots': views.robot_rows(fleet, mission, wall),
            'story': views.story(fleet, mission, wall), 'missions': views.missions(fleet),
            'timeline': views.timeline(fleet, mission, wall), 'map': None}


def test_the_page_holds_the_mission_without_its_script():
    parts = parts_of(faulty_mission(), at(20))
    page = Text()
    page.feed(render(PAGE.read_text(), parts))
    text = page.by_id
    assert text['mission-id'] == MISSION
    assert (text['state'], text['revision'], text['jobs']) == ('complete', '2', '3/3')
    assert text['jobs-detail'] == '0 running, 1 aborted, 1 voided'
    assert text['makespan'] == 'planned 10, (revision 1: 10), executed 10'
    assert text['reasons'] == ("Revision 2 re-planned because: robot 'C' failed; job 'J2' "
                               'aborted')
    assert page.rows == ['A', 'B', 'C']
    assert 'C failed' in text['story'] and text['story'].startswith('t=13')
    assert 'demo' in text['missions']
    assert json.loads(text['initial-state']) == parts


def test_names_cannot_break_out_of_the_page():
    parts = {'mission': {'mission_id': '</script><img src=x>', 'state': 'executing'},
             'robots': [{'robot': '<b>R1</b>', 'mode': 'idle'}]}
    html = render(PAGE.read_text(), parts)
    assert '<img' not in html and '<b>' not in html
    embedded = re.search(r'<script id="initial-state" type="application/json">(.*?)</script>',
                         html, re.S).group(1)
    assert json.loads(embedded) == parts


def test_a_page_before_any_mission_says_so():
    page = Text()
    page.feed(render(PAGE.read_text(), {
        'mission': {'mission_id': '', 'scenario': '', 'state': 'no mission yet',
                    'planner': 'idle'}, 'robots': [], 'missions': []}))
    assert (page.by_id['mission-id'], page.by_id['state']) == ('-', 'no mission yet')
    assert page.by_id['planner'] == 'planner: idle'
    assert '$' not in page.by_id['jobs'] + page.by_id['makespan']
