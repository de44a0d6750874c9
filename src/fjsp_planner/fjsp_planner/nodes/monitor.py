"""A fleet-level mission monitor built only on the public topics.

It shows one line per robot and a mission line while the mission runs (a robot whose
heartbeat is lost shows as offline) and, once it is complete, logs a summary and draws the
planned and executed timelines into a PNG. Everything it needs is latched (plan, states,
status) or kept for late joiners (task events), so it can be started at any time, even after
the mission ended.
"""

import math
import sys
from pathlib import Path

import rclpy
from rclpy.node import Node
from rclpy.time import Time

from fjsp_common.contract import (
    EVENTS_QOS,
    LATCHED_QOS,
    MISSION_STATUS_TOPIC,
    MODE_FROM_MSG,
    PLAN_TOPIC,
    ROBOT_STATES_QOS,
    ROBOT_STATES_TOPIC,
    STATE_FROM_MSG,
    TASK_EVENTS_TOPIC,
)
from fjsp_common.running import declare, run_node
from fjsp_msgs.msg import MissionStatus, Plan, RobotState, TaskEvent


class MonitorNode(Node):
    def __init__(self):
        super().__init__('monitor')
        self.gantt_dir = Path(declare(self, 'gantt_dir', '.',
                                      'directory the Gantt charts are written to')).expanduser()
        refresh_period = declare(self, 'refresh_period', 1.0,
                                 'seconds between refreshes of the view', low=0.05, high=60.0)
        self.heartbeat_timeout = declare(
            self, 'heartbeat_timeout', 1.0,
            'seconds without a robot state before the robot shows offline', low=0.05,
            high=600.0)
        self.exit_on_complete = declare(self, 'exit_on_complete', False,
                                        'exit once the mission is complete and drawn')
        # Events may reach a late joiner after the status saying the mission is complete.
        self.event_grace = declare(
            self, 'event_grace', 3.0,
            'seconds to wait for late task events once the mission is complete', low=0.0,
            high=600.0)
        self.plan: Plan | None = None
        self.status: MissionStatus | None = None
        self.robots: dict[str, RobotState] = {}
        self.heard: dict[str, Time] = {}
        """When each robot's latest state was received."""
        self.started: dict[tuple[str, str], float] = {}
        self.job_done: dict[str, float] = {}
        self.event_ids: set[str] = set()
        self.shown = None
        self.complete_since = None
        self.reported: set[tuple] = set()
        self.finished = False

        self.create_subscription(Plan, PLAN_TOPIC, self.on_plan, LATCHED_QOS)
        self.create_subscription(RobotState, ROBOT_STATES_TOPIC, self.on_robot,
                                 ROBOT_STATES_QOS)
        self.create_subscription(MissionStatus, MISSION_STATUS_TOPIC, self.on_status,
                                 LATCHED_QOS)
        self.create_subscription(TaskEvent, TASK_EVENTS_TOPIC, self.on_event, EVENTS_QOS)
        self.create_timer(refresh_period, self.refresh)

    def on_plan(self, msg: Plan) -> None:
        if self.plan is None or msg.revision > self.plan.revision:
            self.plan = msg

    def on_robot(self, msg: RobotState) -> None:
        self.robots[msg.robot] = msg
        self.heard[msg.robot] = self.get_clock().now()

    def on_status(self, msg: MissionStatus) -> None:
        self.status = msg

    def on_event(self, msg: TaskEvent) -> None:
        if msg.event_id in self.event_ids:
            return
        self.event_ids.add(msg.event_id)
        if msg.kind == TaskEvent.KIND_STARTED:
            self.started[msg.robot, msg.job] = msg.time
        elif msg.kind == TaskEvent.KIND_JOB_DONE:
            self.job_done[msg.job] = msg.time
        elif msg.kind == TaskEvent.KIND_ABORTED:
            self.started.pop((msg.robot, msg.job), None)

    # --- the live view ---------------------------------------------------------------

    def view(self) -> str:
        lines = []
        s = self.status
        if s is None:
            lines.append('mission: no status yet (is the planner running?)')
        else:
            lines.append(
                f'mission {s.scenario_id} rev {s.plan_revision}: '
                f'{STATE_FROM_MSG.get(s.state, s.state)}, {s.jobs_done}/{s.jobs_total} jobs '
                f'done, {s.jobs_running} running, makespan planned {s.planned_makespan:.2f} '
                f'projected {s.projected_makespan:.2f}, t={s.elapsed:.1f}'
                + (f', ignored {s.ignored_stale} stale / {s.ignored_duplicate} duplicate / '
                   f'{s.ignored_unknown} unknown'
                   if s.ignored_stale + s.ignored_duplicate + s.ignored_unknown else ''))
            lines += [f'  blocked: {reason}' for reason in s.blocked_reasons]
        names = [r.robot for r in self.plan.robots] if self.plan else []
        names += sorted(set(self.robots) - set(names))
        now = self.get_clock().now()
        for name in names:
            r = self.robots.get(name)
            if r is None:
                lines.append(f'  {name:<10} no report')
                continue
            silent = (now - self.heard[name]).nanoseconds * 1e-9
            if silent > self.heartbeat_timeout:
                mode = 'offline'
            else:
                mode = MODE_FROM_MSG.get(r.mode, f'mode {r.mode}')
            where = (f'{r.location or "?"} -> {r.destination}' if r.destination
                     else r.location or '-')
            lines.append(f'  {name:<10} {mode:<10} job {r.current_job or "-":<4} '
                         f'{r.progress:4.0%}  at {where}')
        return '\n'.join(lines)

    def refresh(self) -> None:
        view = self.view()
        if view != self.shown:
            self.shown = view
            self.get_logger().info('\n' + view)
        self.check_complete()

    # --- the end of a mission --------------------------------------------------------

    def check_complete(self) -> None:
        s, plan = self.status, self.plan
        if s is None or plan is None or s.state != MissionStatus.STATE_COMPLETE \
                or s.plan_revision != plan.revision:
            self.complete_since = None
            return
        key = (s.scenario_id, plan.mission_start.sec, plan.mission_start.nanosec,
               plan.revision)
        if key in self.reported:
            return
        jobs = {t.job for r in plan.robots for t in r.tasks}
        now = self.get_clock().now()
        if self.complete_since is None:
            self.complete_since = now
        waited = (now - self.complete_since).nanoseconds * 1e-9
        if not jobs <= set(self.job_done) and waited < self.event_grace:
            return
        self.reported.add(key)
        path = self.gantt_dir / (f'{s.scenario_id}_{plan.mission_start.sec}_'
                                 f'r{plan.revision}.png')
        log = self.get_logger()
        try:
            draw(plan, self.started, self.job_done, path)
            where = f'Gantt chart: {path.resolve()}'
        except OSError as error:
            where = f'could not write the Gantt chart {path}: {error.strerror}'
            log.error(where)
        executed = max(self.job_done.values(), default=math.nan)
        log.info(f'mission {s.scenario_id} complete: {len(jobs & set(self.job_done))}/'
                 f'{len(jobs)} jobs done; makespan planned {plan.makespan:.2f}, executed '
                 f'{executed:.2f} schedule units; {where}')
        if self.exit_on_complete:
            self.finished = True


def draw(plan: Plan, started, job_done, path: Path) -> None:
    """Planned (upper, light) and executed (lower, solid) bars per robot, travel as lines."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    robots = [r.robot for r in plan.robots]
    fig, ax = plt.subplots(figsize=(11, 1.0 + 0.8 * len(robots)))
    colours = plt.get_cmap('tab20')
    jobs = sorted({t.job for r in plan.robots for t in r.tasks})
    colour = {job: colours(i % 20) for i, job in enumerate(jobs)}
    for y, robot_plan in enumerate(plan.robots):
        for t in robot_plan.tasks:
            if t.arrival > t.travel_start:
                ax.plot([t.travel_start, t.arrival], [y - 0.2, y - 0.2], color='grey', lw=1)
            ax.barh(y - 0.2, t.end - t.start, left=t.start, height=0.35,
                    color=colour[t.job], alpha=0.45, edgecolor='black', hatch='//')
            ax.text((t.start + t.end) / 2, y - 0.2, t.job, ha='center', va='center',
                    fontsize=7)
            begin = started.get((robot_plan.robot, t.job))
            end = job_done.get(t.job)
            if begin is not None and end is not None:
                ax.barh(y + 0.2, end - begin, left=begin, height=0.35, color=colour[t.job],
                        edgecolor='black')
                ax.text((begin + end) / 2, y + 0.2, t.job, ha='center', va='center',
                        fontsize=7)
    ax.set_yticks(range(len(robots)), robots)
    ax.invert_yaxis()  # first robot on top; within a row, planned above executed
    ax.set_xlabel('schedule time units (upper bar: planned, lower bar: executed)')
    executed = max(job_done.values(), default=math.nan)
    ax.set_title(f'{plan.scenario_id}, plan revision {plan.revision}: planned makespan '
                 f'{plan.makespan:.2f}, executed {executed:.2f}')
    ax.grid(axis='x', alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def spin_until_finished(node: 'MonitorNode') -> None:
    while rclpy.ok() and not node.finished:
        rclpy.spin_once(node, timeout_sec=0.2)


def main(args=None):
    sys.exit(run_node(MonitorNode, 'monitor', args, spin=spin_until_finished))
