"""The paper's schedule chart (Figs. 5-6): a row per robot, a coloured bar per job, black
lines for travel, the makespan marked. An executed timeline can be drawn under the plan.

However long the schedule, the chart is at most `chart_layout.MAX_WIDTH` wide; a bar too
short for its job's name at that scale shows the name shortened, or none (`chart_layout`)."""

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)

from fjsp_common.decimals import decimal  # noqa: E402
from fjsp_planner.model.problem import Problem  # noqa: E402
from fjsp_planner.model.schedule import Schedule  # noqa: E402
from fjsp_planner.observe.chart_layout import DPI, BarLabels, Drawn, chart_width, saved  # noqa: E402

ROW_HEIGHT = 0.8
"""Inches per robot."""


def draw_gantt(problem: Problem, schedule: Schedule, path, title: str = '',
               executed: Schedule | None = None) -> Drawn:
    """Write the chart of `schedule` (and `executed` under it) to `path` (PNG)."""
    robots = [r.name for r in problem.robots]
    names = sorted(schedule.jobs)
    palette = plt.get_cmap('tab20')
    colour = {name: palette(i % 20) for i, name in enumerate(names)}
    rows = [(schedule, 0.0, 0.6 if executed is None else 0.38, 'planned')]
    if executed is not None:
        rows.append((executed, -0.4, 0.3, 'executed'))
    span = max([float(schedule.makespan)] + ([float(executed.makespan)] if executed else []))
    fig, ax = plt.subplots(figsize=(chart_width(span, 0.16, 4.0, 8.0),
                                    1.0 + ROW_HEIGHT * len(robots)), dpi=DPI)
    labels = BarLabels(ax)
    for timeline, offset, height, _ in rows:
        for y, robot in enumerate(robots):
            centre = len(robots) - 1 - y + offset
            for visit in _visits(problem, timeline, robot):
                if visit.arrival > visit.travel_start:
                    ax.plot([float(visit.travel_start), float(visit.arrival)], [centre, centre],
                            color='black', linewidth=2)
                a = timeline.jobs[visit.job]
                ax.barh(centre, float(a.end - a.start), left=float(a.start), height=height,
                        color=colour.get(visit.job, 'grey'), edgecolor='black',
                        hatch='//' if timeline is executed else None)
                labels.add(visit.job, float(a.start), float(a.end), centre)
    for timeline, _, _, label in rows:
        style = '--' if label == 'planned' else ':'
        ax.axvline(float(timeline.makespan), color='red', linestyle=style)
        ax.text(float(timeline.makespan), len(robots) - 0.45,
                f' {label} makespan {decimal(timeline.makespan)}', color='red', fontsize=8)
    ax.set_yticks(range(len(robots)), list(reversed(robots)))
    ax.set_xlabel('time (schedule units)')
    ax.set_xlim(left=0)
    ax.set_title(title or problem.name)
    fig.tight_layout()
    return saved(fig, path, labels.write())


def _visits(problem, schedule, robot):
    if robot not in schedule.sequences:
        return []
    return schedule.visits(problem, robot)
