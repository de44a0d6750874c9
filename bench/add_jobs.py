"""Jobs added mid-mission: time from an AddJobs request to every agent following the revision
that plans them in, for a 1-panel and a 5-panel mission of the paper's solar panel, each
extended by one more panel.

Each trial submits a mission to an idle fleet (planner + the paper's four agents), waits
until it is under way, adds a panel's twelve jobs, measures, and cancels the mission so the
next trial starts afresh on the same fleet. Prints figures, never asserts.

Run from the repository with the workspace sourced:
    source ros2_ws/env.sh && nice -n 10 python bench/add_jobs.py [--trials 5] [--panels 1 5]
"""

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import yaml

from fjsp_planner.missions import MissionClient
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.testing import FleetHarness

REPO = Path(__file__).resolve().parents[1]
SCENARIO = REPO / 'config' / 'scenarios' / 'solar_panel.yaml'
SHIFT = 60


def one_more_panel(panels: int) -> str:
    """The fragment adding panel `panels + 1` to an N-panel mission of the solar panel: its
    jobs, their precedence and holding arcs, and the distances from its places to all."""
    base = load_scenario(SCENARIO)

    def tag(name, k):
        return name if panels == 1 and k == 1 else f'{name}_p{k}'

    new = panels + 1
    places = base.locations()
    pairs = [[tag(a, new), tag(b, new), str(base.distance(a, b))]
             for i, a in enumerate(places) for b in places[i + 1:]]
    pairs += [[tag(a, new), tag(b, k), str(base.distance(a, b) + SHIFT * (new - k))]
              for k in range(1, new) for a in places for b in places]
    return yaml.safe_dump({
        'jobs': [{'name': tag(j.name, new), 'location': tag(j.location, new),
                  'plans': [list(p) for p in j.plans]} for j in base.jobs],
        'distances': {'pairs': pairs},
        'precedence': [[tag(a, new), tag(b, new)] for a, b in base.precedence],
        'holding': [[tag(a, new), tag(b, new), q] for a, b, q in base.holding]})


def trial(fleet: FleetHarness, client: MissionClient, panels: int, args) -> float:
    observer = fleet.observer
    mission = client.submit(SCENARIO, panels=panels, time_scale=args.time_scale,
                            time_limit=args.time_limit, timeout=30)
    observer.wait_for(lambda o: o.status is not None
                      and o.status.mission_id == mission.mission_id
                      and o.status.jobs_done >= 2, args.timeout, 'the mission under way')
    began = time.monotonic()
    added = set(client.add_jobs(fragment_yaml=one_more_panel(panels),
                                mission_id=mission.mission_id))

    def followed(o) -> bool:
        plans = [p for p in o.plans if p.mission_id == mission.mission_id
                 and added & {t.job for r in p.robots for t in r.tasks}]
        return bool(plans) and all(o.robots[r].plan_revision >= plans[0].revision
                                   for r in ('Assembler', 'LSMS', 'MARC1', 'MARC2'))

    observer.wait_for(followed, args.timeout, 'every agent to follow the extended plan')
    latency = time.monotonic() - began
    client.cancel(mission.mission_id, reason='bench trial over')
    mission.result(timeout=30)
    return latency


def main(argv) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--panels', type=int, nargs='+', default=[1, 5])
    parser.add_argument('--trials', type=int, default=5)
    parser.add_argument('--time-scale', type=float, default=0.2,
                        help='wall seconds per schedule unit (slow: the jobs land mid-mission)')
    parser.add_argument('--time-limit', type=float, default=10.0, help='first plan, seconds')
    parser.add_argument('--replan-time-limit', type=float, default=1.0)
    parser.add_argument('--timeout', type=float, default=120.0)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix='fjsp-bench-add-jobs-') as out:
        fleet = FleetHarness(SCENARIO, out=Path(out),
                             planner={'replan_time_limit': args.replan_time_limit})
        try:
            fleet.start_planner(scenario='')
            for robot in fleet.problem.robots:
                fleet.start_agent(robot.name)
            fleet.wait_for(lambda o: len(o.robots) == 4, 60, 'the four agents')
            with MissionClient(domain_id=fleet.domain) as client:
                print(f'AddJobs of one more panel -> every agent follows the new revision '
                      f'({args.trials} trials, re-plan limit {args.replan_time_limit:g} s)')
                print(f"{'panels':>6} {'+jobs':>6} {'p50 s':>7} {'p95 s':>7} {'max s':>7}")
                for panels in args.panels:
                    latencies = sorted(trial(fleet, client, panels, args)
                                       for _ in range(args.trials))
                    p95 = latencies[min(len(latencies) - 1, int(0.95 * len(latencies)))]
                    print(f'{panels:>6} {12:>6} {statistics.median(latencies):>7.2f} '
                          f'{p95:>7.2f} {latencies[-1]:>7.2f}', flush=True)
        finally:
            fleet.close()
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
