"""`ros2 run fjsp_planner replay FILE.mcap`: the post-mortem of a recorded fleet.

Rebuilds every mission of the recording from the messages alone (no ROS, no running fleet),
prints what the recording holds, each mission's summary and story, and draws each mission's
Gantt chart (with its data as JSON beside it) as the live monitor does. Given the fleet key
(`--key-file`, else the file $FJSP_FLEET_KEY_FILE names), it believes only what verifies
with it, as the fleet's nodes did, and says what it left out. Exit code 0 when at least one
mission was found, 1 when the file cannot be read or holds none, 2 for bad arguments.
"""

import argparse
import os
import sys
from pathlib import Path

from fjsp_common.auth import KEY_FILE_VARIABLE, FleetKeyError, read_key
from fjsp_common.fleet import HEARTBEAT_TIMEOUT
from fjsp_planner.observe import text, views
from fjsp_planner.observe.mission_chart import write_mission
from fjsp_planner.observe.recording import RecordingError, replay
from fjsp_planner.workspace import safe_file_name


def positive(value: str) -> float:
    try:
        number = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f'expected a number, got {value!r}') from None
    if not number > 0:
        raise argparse.ArgumentTypeError(f'must be > 0, got {value}')
    return number


def parse(argv):
    parser = argparse.ArgumentParser(
        prog='replay', description='Rebuild the missions of a fleet recording (.mcap): '
        'summary, story and Gantt chart of each.')
    parser.add_argument('recording', type=Path, help='the .mcap file the recorder wrote')
    parser.add_argument('--out', type=Path, default=None,
                        help="directory of the charts (default: the recording's)")
    parser.add_argument('--mission', default='',
                        help='only this mission id (default: every mission recorded)')
    parser.add_argument('--heartbeat-timeout', type=positive, default=HEARTBEAT_TIMEOUT,
                        help='seconds without a robot state that count as offline '
                        f'(default {HEARTBEAT_TIMEOUT}, as the nodes)')
    parser.add_argument('--no-chart', action='store_true', help='print only, draw nothing')
    parser.add_argument('--key-file', type=Path, default=None,
                        help='fleet key to verify the messages with (default: '
                        f'${KEY_FILE_VARIABLE}; none: every message is believed)')
    return parser.parse_args(argv)


def main(argv=None) -> int:
    args = parse(sys.argv[1:] if argv is None else argv)
    key_file = args.key_file or os.environ.get(KEY_FILE_VARIABLE) or None
    try:
        key = read_key(key_file) if key_file else None
    except FleetKeyError as error:
        print(f'replay: {error}', file=sys.stderr)
        return 2
    try:
        fleet, reading = replay(args.recording, args.heartbeat_timeout, key)
    except RecordingError as error:
        print(f'replay: {error}', file=sys.stderr)
        return 1
    print(f'recording {args.recording}: {reading.counts.total()} messages')
    for topic in sorted(reading.counts):
        print(f'  {topic:<20} {reading.types.get(topic, "?"):<36} {reading.counts[topic]:>7}')
    for topic, count in sorted(reading.undecodable.items()):
        print(f'  {topic}: {count} message(s) could not be read')
    if reading.truncated:
        print(f'  the recording stops short (its recorder did not finish it): '
              f'{reading.truncated}')
    for topic, count in sorted(reading.dropped_by_recorder.items()):
        print(f'  {topic}: the recorder dropped {count} message(s) that did not verify with '
              'the fleet key')
    for topic, count in sorted(reading.unverified.items()):
        print(f'  {topic}: {count} message(s) left out: they do not verify with the fleet key')
    if reading.unverified:
        print('  (' + '; '.join(f'{n} {why}' for why, n in reading.unverified_why.most_common())
              + ')')
    if key is None:
        print('  not verified: no fleet key given (--key-file, or '
              f'{KEY_FILE_VARIABLE}); every message is believed')
    missions = [m for m in fleet.missions.values() if m.plans or m.status is not None]
    if args.mission:
        missions = [m for m in missions if m.mission_id == args.mission]
    if not missions:
        which = f"mission '{args.mission}'" if args.mission else 'any mission'
        print(f'replay: {args.recording} holds no {which}', file=sys.stderr)
        return 1
    out = args.out if args.out is not None else args.recording.resolve().parent
    wall = reading.last_time
    for mission in sorted(missions, key=lambda m: m.last_stamp):
        print()
        print(text.summary(mission))
        for item in views.story(fleet, mission, wall):
            print('  ' + text.story_line(item))
        if not args.no_chart:
            png = out / f'{safe_file_name(mission.mission_id)}.replay.png'
            try:
                write_mission(fleet, mission, wall, png)
            except OSError as error:
                print(f'replay: cannot write {png}: {error.strerror or error}',
                      file=sys.stderr)
                return 1
            print(f'  Gantt chart: {png}')
    return 0


def run():
    sys.exit(main())
