"""The paper's schedule chart (Figs. 5-6): a row per robot, a coloured bar per job, black
lines for travel, the makespan marked. An executed timeline can be drawn under the plan."""

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)

from fjsp_planner.model.problem import Problem  # noqa: E402
from fjsp_planner.model.schedule import Schedule  # noqa: E402


def draw_gantt(problem: Problem, schedule: Schedule, path, title: str = '',
               executed: Schedule | None = None) -> None:
    robots = [r.name for r in problem.robots]
    names = sorted(schedule.jobs)
    palette = plt.get_cmap('tab20')
    colour = {name: palette(i % 20) for i, name in enumerate(names)}
    rows = [(schedule, 0.0, 0.6 if executed is None else 0.38, 'planned')]
    if executed is not None:
        rows.append((executed, -0.4, 0.3, 'executed'))
    fig, ax = plt.subplots(figsize=(max(8.0, 0.16 * float(schedule.makespan) + 4),
                                    1.0 + 0.8 * len(robots)))
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
                ax.text(float(a.start + a.end) / 2, centre, visit.job, ha='center',
                        va='center', fontsize=7)
    for timeline, _, _, label in rows:
        style = '--' if label == 'planned' else ':'
        ax.axvline(float(timeline.makespan), color='red', linestyle=style)
        ax.text(float(timeline.makespan), len(robots) - 0.45,
                f' {label} makespan {float(timeline.makespan):g}', color='red', fontsize=8)
    ax.set_yticks(range(len(robots)), list(reversed(robots)))
    ax.set_xlabel('time (schedule units)')
    ax.set_xlim(left=0)
    ax.set_title(title or problem.name)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _visits(problem, schedule, robot):
    if robot not in schedule.sequences:
        return []
    return schedule.visits(problem, robot)
