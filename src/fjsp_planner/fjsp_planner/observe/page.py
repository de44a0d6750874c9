"""The live page as its server sends it: the mission already written into the HTML.

A page that filled only through its event stream showed nothing until the first update
arrived: a screenshot taken on load could come out blank, and `curl` of the page, or a
browser without JavaScript, showed no mission at all. So the server writes the mission line,
the reasons in force, the robots, the events and the missions into the page it sends, and
embeds every part as JSON, which the script draws at once (timeline and map included)
before it listens for updates.

`render` takes the template (`web/index.html`, whose `$name` placeholders it fills) and
the parts the monitor published (`Dashboard.publish`), and escapes every value: names come
from scenario files and messages.
"""

import json
from html import escape
from string import Template

from fjsp_common.decimals import decimals


def _times(*values) -> tuple[str, ...]:
    """Times written together as everywhere a person reads them; '-' for an unknown one, as
    the page's script writes it."""
    return tuple('-' if value is None else text
                 for value, text in zip(values, decimals(*values), strict=True))


def _cells(*cells: tuple[str, str]) -> str:
    return ''.join(f'<td class="{kind}">{escape(str(text))}</td>' for kind, text in cells)


def _makespan(m: dict) -> str:
    ended = m.get('ended')
    planned, first, outcome = _times(
        m.get('planned_makespan'), m.get('first_makespan'),
        m.get('executed_makespan') if ended else m.get('projected_makespan'))
    parts = [f'planned {planned}']
    if m.get('revision', 0) > 1:
        parts.append(f'(revision 1: {first})')
    parts.append(f'executed {outcome}' if ended else f'projected {outcome}')
    return ', '.join(parts)


def _jobs_detail(m: dict) -> str:
    detail = [f"{m.get('jobs_running', 0)} running"]
    if m.get('aborted_attempts'):
        detail.append(f"{m['aborted_attempts']} aborted")
    if m.get('voided_attempts'):
        detail.append(f"{m['voided_attempts']} voided")
    if m.get('status_jobs') and not m.get('agrees'):
        detail.append(f"planner says {m['status_jobs'][0]}/{m['status_jobs'][1]}")
    return ', '.join(detail)


def _reasons(m: dict) -> str:
    lines = []
    if m.get('revision', 0) > 1 and m.get('replan_reasons'):
        lines.append(('replan', f"Revision {m['revision']} re-planned because: "
                      + '; '.join(m['replan_reasons'])))
    lines += [('warning', f'Warning: {w}') for w in m.get('warnings', [])]
    label = m.get('reasons_label', 'Blocked')
    lines += [('blocked', f'{label}: {b}') for b in m.get('blocked_reasons', [])]
    return ''.join(f'<div class="{kind}">{escape(text)}</div>' for kind, text in lines)


def _robot_row(r: dict) -> str:
    moving = r.get('mode') in ('travelling', 'working')
    progress = f"{round((r.get('progress') or 0) * 100)}%" if moving else ''
    where = (f"{r.get('location') or '?'} \u2192 {r['destination']}" if r.get('destination')
             else r.get('location') or '-')
    mode = escape(r.get('mode', ''))
    return (f'<tr data-robot="{escape(r["robot"])}">'
            + _cells(('name', r['robot']), ('type', r.get('type') or ''))
            + f'<td class="mode"><span data-mode="{mode}">{mode}</span></td>'
            + _cells(('job', r.get('job') or '-'), ('progress', progress), ('where', where),
                     ('detail', r.get('detail') or ''))
            + '</tr>')


def _story_line(item: dict) -> str:
    return (f'<li data-kind="{escape(item["kind"])}" data-key="{escape(item["key"])}">'
            f'<span class="t">t={_times(item.get("time"))[0]}</span>'
            f'{escape(item["text"])}</li>')


def _mission_row(m: dict) -> str:
    return (f'<tr data-mission="{escape(m["mission_id"])}">'
            + _cells(('', m['mission_id']), ('', m['scenario']), ('', m['state']),
                     ('', f"{m['jobs_done']}/{m['jobs_total']}"))
            + '</tr>')


def render(template: str, parts: dict) -> str:
    """The page with `parts` (name -> data, as published) written in and embedded."""
    m = parts.get('mission') or {}
    placed = bool(m.get('mission_id'))
    fields = {
        'mission_id': m.get('mission_id') or '-',
        'scenario': f"scenario {m['scenario']}" if placed and m.get('scenario') else '',
        'state': m.get('state', '-'),
        'revision': m.get('revision', '-') if placed else '-',
        'jobs': f"{m.get('jobs_done', 0)}/{m.get('jobs_total', 0)}" if placed else '-',
        'jobs_total': max(m.get('jobs_total', 0), 1) if placed else 1,
        'jobs_done': m.get('jobs_done', 0) if placed else 0,
        'jobs_detail': _jobs_detail(m) if placed else '',
        'time': _times(m.get('time'))[0] if placed else '-',
        'makespan': _makespan(m) if placed else '-',
        'planner': f"planner: {m['planner']}" if m.get('planner') else '',
    }
    html = {name: escape(str(value)) for name, value in fields.items()}
    html.update(
        reasons=_reasons(m) if placed else '',
        robot_rows=''.join(_robot_row(r) for r in parts.get('robots') or []),
        story_lines=''.join(_story_line(i) for i in reversed(parts.get('story') or [])),
        mission_rows=''.join(_mission_row(r) for r in reversed(parts.get('missions') or [])),
        map_hidden='' if parts.get('map') else ' hidden',
        # Inside <script>, '</script>' in a name must not end the element: no '<' at all.
        initial=json.dumps(parts, separators=(',', ':'), allow_nan=False).replace(
            '<', '\\u003c'))
    return Template(template).substitute(html)
