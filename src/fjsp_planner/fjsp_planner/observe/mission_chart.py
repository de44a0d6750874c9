"""The Gantt chart of a whole mission: one row per robot, with what was planned (the first
and the latest revision), the work done in every attempt (aborted and voided ones marked),
travel, waiting and holds, failed and offline spans, and a line where each revision was
published with the reasons listed under the chart.

It draws `views.timeline` data, the same the web page draws, so the PNG written at the end of
a mission (or by `replay`) and the live page show one picture. However long the mission, the
chart is at most `chart_layout.MAX_WIDTH` wide, and a bar too short for its job's name at that
scale shows the name shortened, or none.
"""

import json
from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from fjsp_common.decimals import decimal, decimals  # noqa: E402
from fjsp_planner.observe import views  # noqa: E402
from fjsp_planner.observe.chart_layout import DPI, BarLabels, Drawn, chart_width, saved  # noqa: E402
from fjsp_planner.observe.history import FleetHistory, MissionHistory  # noqa: E402

FIRST_PLAN, LAST_PLAN, WORK, ACTIVITY = 0.34, 0.18, -0.04, -0.3
"""Offsets of the lanes within a robot's row (row height 1)."""
OUTCOME_STYLE = {
    'done': {'alpha': 1.0, 'hatch': None, 'edgecolor': 'black'},
    'running': {'alpha': 0.9, 'hatch': None, 'edgecolor': 'black', 'linestyle': ':'},
    'aborted': {'alpha': 0.6, 'hatch': 'xx', 'edgecolor': 'red'},
    'voided': {'alpha': 0.35, 'hatch': '\\\\', 'edgecolor': 'dimgrey'},
}
ACTIVITY_STYLE = {
    'travelling': {'color': 'black', 'linewidth': 1.6, 'linestyle': '-'},
    'waiting': {'color': 'grey', 'linewidth': 1.2, 'linestyle': ':'},
    'holding': {'color': 'royalblue', 'linewidth': 3.0, 'linestyle': '-'},
}
HEALTH_COLOUR = {'failed': ('red', 0.14), 'offline': ('grey', 0.28)}
MAX_ROWS = 100
"""Robots drawn, in the timeline's order."""
MAX_NOTES = 12
"""Revisions whose reasons are listed under the chart."""
LABEL = 30
"""Characters of a robot's name shown."""


def job_colours(jobs) -> dict:
    palette = plt.get_cmap('tab20')
    return {job: palette(index % 20) for index, job in enumerate(sorted(set(jobs)))}


def draw_mission(timeline: dict, header: dict, path: Path) -> Drawn:
    """Write the chart of `timeline` (from `views.timeline`) to `path` (PNG)."""
    # What a figure can hold whatever a recording names: a forged flood of robot names or
    # of re-plans must not make an image too large to draw.
    robots = timeline['robots'][:MAX_ROWS]
    rows = {robot: len(robots) - 1 - index for index, robot in enumerate(robots)}
    end = max(timeline['end'] or 1.0, 1.0)
    now_units = timeline['now']
    colour = job_colours([w['job'] for w in timeline['work']]
                         + [t['job'] for p in timeline['plans'] for t in p['tasks']])
    notes = [f"r{r['number']} at t={decimal(r['time'])}: "
             + ('; '.join(r['reasons']) or 'no reason given')
             for r in timeline['revisions'] if r['number'] > 1 and r['time'] is not None]
    if len(notes) > MAX_NOTES:
        notes = notes[:MAX_NOTES - 1] + [f'... and {len(notes) - MAX_NOTES + 1} more '
                                         'revisions']
    notes = [_cut(note, 300) for note in notes]
    # Heights in inches: title, one per robot, axis and legend, a line per revision's reasons.
    below = 1.1 + 0.17 * len(notes)
    height = 0.65 + 0.95 * len(robots) + below
    width = chart_width(end, 0.1, 7.0, 11.0)
    fig, ax = plt.subplots(figsize=(width, height), dpi=DPI)
    labels = BarLabels(ax)
    label = 0.2 + 0.075 * max((min(len(r), LABEL) for r in robots), default=4)
    fig.subplots_adjust(left=label / width, right=0.99, top=1 - 0.55 / height,
                        bottom=below / height)

    def clip(value):
        """A time where the chart can draw it: an open end is the chart's end, and a time
        off the axes is drawn at the nearest edge (a bar of hostile length rendered whole
        takes the renderer for ever)."""
        return end if value is None else min(max(value, 0.0), end * 1.02)

    for span in timeline['health']:
        if span['robot'] in rows:
            y = rows[span['robot']]
            colour_, alpha = HEALTH_COLOUR.get(span['kind'], ('grey', 0.2))
            start, stop = clip(span['start']), clip(now_units if span['open'] else span['end'])
            ax.barh(y, stop - start, left=start, height=0.96, color=colour_, alpha=alpha, lw=0)
            ax.plot([start], [y + 0.44], marker='X', color='red', markersize=9)
            if not span['open']:
                ax.plot([stop], [y + 0.44], marker='^', color='green', markersize=8)
    lanes = [FIRST_PLAN, LAST_PLAN] if len(timeline['plans']) > 1 else [(FIRST_PLAN +
                                                                         LAST_PLAN) / 2]
    for plan, lane in zip(timeline['plans'], lanes, strict=False):
        latest = plan is timeline['plans'][-1] and len(timeline['plans']) > 1
        for t in plan['tasks']:
            if t['robot'] not in rows:
                continue
            y = rows[t['robot']] + lane
            if t['arrival'] > t['travel_start']:
                ax.plot([clip(t['travel_start']), clip(t['arrival'])], [y, y], color='grey',
                        lw=0.8)
            ax.barh(y, clip(t['end']) - clip(t['start']), left=clip(t['start']), height=0.12,
                    color=colour[t['job']] if latest else 'none', alpha=0.45 if latest else 1,
                    edgecolor=colour[t['job']] if latest else 'dimgrey',
                    linestyle='-' if latest else '--', lw=0.8)
    for w in timeline['work']:
        if w['robot'] not in rows:
            continue
        y = rows[w['robot']] + WORK
        start, stop = clip(w['start']), clip(now_units if w['open'] else w['end'])
        style = OUTCOME_STYLE.get(w['outcome'], OUTCOME_STYLE['done'])
        ax.barh(y, max(stop - start, 0.05), left=start, height=0.3, color=colour[w['job']],
                **style)
        if 0 <= (w['start'] + stop) / 2 <= end:  # a text far off the axes cannot be placed
            labels.add(w['job'] + (f"#{w['attempt']}" if w['attempt'] > 1 else ''), start,
                       stop, y, color='black' if w['outcome'] != 'voided' else 'dimgrey')
    for a in timeline['activities']:
        style = ACTIVITY_STYLE.get(a['mode'])
        if style and a['robot'] in rows:
            start, stop = clip(a['start']), clip(now_units if a['open'] else a['end'])
            if stop > start:
                y = rows[a['robot']] + ACTIVITY
                ax.plot([start, stop], [y, y], solid_capstyle='butt', **style)
    for r in timeline['revisions']:
        if r['time'] is None:
            continue
        x = max(r['time'], 0.0)
        if x > end:
            continue
        ax.axvline(x, color='purple', linestyle='--', lw=1)
        ax.text(x, len(robots) - 0.45, f" r{r['number']}", color='purple', fontsize=8,
                va='bottom')
    if now_units is not None and not header['ended'] and 0 <= now_units <= end:
        ax.axvline(now_units, color='black', lw=1.2)
        ax.text(now_units, -0.62, ' now', fontsize=8)
    ax.set_yticks(range(len(robots)), [_cut(r, LABEL) for r in reversed(robots)])
    ax.set_ylim(-0.65, len(robots) - 0.3)
    ax.set_xlim(0, end * 1.02)
    ax.grid(axis='x', alpha=0.25)
    ax.set_xlabel('schedule time units')
    ax.set_title(_title(header), fontsize=10)
    fig.legend(handles=_legend(len(timeline['plans'])), loc='lower center', fontsize=7,
               ncol=7, bbox_to_anchor=(0.5, (0.08 + 0.17 * len(notes)) / height),
               frameon=False)
    if notes:
        fig.text(0.01, 0.06 / height, '\n'.join(notes), fontsize=7.5, va='bottom')
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return saved(fig, path, labels.write())


def write_mission(fleet: FleetHistory, mission: MissionHistory, wall: float, png: Path) -> None:
    """The mission's chart to `png`, and what it was drawn from beside it (`.json`: the
    mission line, the timeline and the story, for other tools)."""
    header, timeline = views.header(mission, wall), views.timeline(fleet, mission, wall)
    draw_mission(timeline, header, png)
    Path(png).with_suffix('.json').write_text(json.dumps(
        {'mission': header, 'timeline': timeline, 'story': views.story(fleet, mission, wall)},
        indent=1, allow_nan=False))


def _title(h: dict) -> str:
    agree = '' if h['agrees'] or not h['status_jobs'] else \
        f" (planner says {h['status_jobs'][0]}/{h['status_jobs'][1]})"
    first, latest, executed = decimals(h['first_makespan'], h['planned_makespan'],
                                       h['executed_makespan'])
    return (f"{h['scenario']} - mission {h['mission_id']}: {h['state']}, "
            f"{h['jobs_done']}/{h['jobs_total']} jobs done{agree}\nrevision {h['revision']}; "
            f'makespan planned {first} (r1), {latest} (latest), executed {executed}')


def _cut(text: str, length: int) -> str:
    return text if len(text) <= length else text[:length - 1] + '\u2026'


def _legend(plans: int) -> list:
    handles = []
    if plans > 1:
        handles += [Patch(facecolor='none', edgecolor='dimgrey', linestyle='--',
                          label='planned, revision 1'),
                    Patch(facecolor='tab:blue', alpha=0.45, label='planned, latest revision')]
    else:
        handles.append(Patch(facecolor='none', edgecolor='dimgrey', linestyle='--',
                             label='planned'))
    handles += [
        Patch(facecolor='tab:blue', edgecolor='black', label='work done (colour: job)'),
        Patch(facecolor='tab:blue', alpha=0.6, hatch='xx', edgecolor='red',
              label='aborted attempt'),
        Patch(facecolor='tab:blue', alpha=0.35, hatch='\\\\', edgecolor='dimgrey',
              label='voided attempt (redone)'),
        Line2D([], [], **ACTIVITY_STYLE['travelling'], label='travelling'),
        Line2D([], [], **ACTIVITY_STYLE['waiting'], label='waiting'),
        Line2D([], [], **ACTIVITY_STYLE['holding'], label='holding a part'),
        Patch(facecolor='red', alpha=0.14, label='failed'),
        Patch(facecolor='grey', alpha=0.28, label='offline'),
        Line2D([], [], marker='X', color='red', linestyle='none', label='fault'),
        Line2D([], [], marker='^', color='green', linestyle='none', label='back in service'),
        Line2D([], [], color='purple', linestyle='--', label='revision published'),
    ]
    return handles
