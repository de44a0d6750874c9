"""`replay` never fails on what a recording holds: a small mission's messages with fields
swapped for hostile values (NaN, infinite, negative and huge times, empty and enormous names,
unknown ids and constants, extreme counters and stamps) and messages whose recorded schema
gives fields the wrong types are each read, told and drawn, or left out as unreadable, with
exit code 0 or 1 and no exception."""

import math
import random
import re

import pytest
from mcap_ros2._dynamic import serialize_dynamic

from fjsp_planner.observe.recording import Offer, RecordingWriter, message_definition
from fjsp_planner.observe.replay import main

import generated_seeds
from mission_facts import READ_MSG, TOPICS, as_message, faulty_mission

TIMES = ('time', 'travel_start', 'arrival', 'start', 'operation_end', 'end', 'time_scale',
         'makespan', 'lower_bound', 'progress', 'busy_until', 'planned_makespan',
         'projected_makespan', 'elapsed')
NAMES = ('mission_id', 'job', 'robot', 'event_id', 'location', 'reason', 'robot_type',
         'current_job', 'destination', 'operation_name', 'scenario_id', 'solver_status',
         'refusal')
COUNTS = ('revision', 'plan_revision', 'jobs_done', 'jobs_running', 'jobs_total',
          'restarted_in', 'failures', 'process_plan')
CONSTANTS = ('kind', 'mode', 'state', 'operation_type')
LISTS = ('co_workers', 'predecessors', 'reasons', 'warnings', 'blocked_reasons',
         'replan_reasons')

HOSTILE = {
    'time': [math.nan, math.inf, -math.inf, -1e300, 1e300, -5.0, 0.0, 5e-324, 4e11, -4e11],
    'name': ['', 'x' * 5000, 'J9', 'nobody', '\u202e\u0000', 'a\nb', "'"],
    'count': [0, 1, 2 ** 32 - 1, 7],
    'constant': [0, 200, 255],
    'list': [[], [''] * 3, ['x' * 1000] * 50, ['J9', 'J1', 'J1']],
    'stamp': [{'sec': -2 ** 31, 'nanosec': 0}, {'sec': 2 ** 31 - 1, 'nanosec': 999_999_999},
              {'sec': 0, 'nanosec': 0}],
}


def hostile(value, field: str, rng: random.Random):
    """`value` of `field`, or a hostile one of the same wire type."""
    for fields, kind in ((TIMES, 'time'), (NAMES, 'name'), (COUNTS, 'count'),
                         (CONSTANTS, 'constant'), (LISTS, 'list')):
        if field in fields:
            return rng.choice(HOSTILE[kind])
    if field in ('stamp', 'mission_start'):
        return rng.choice(HOSTILE['stamp'])
    return value


def mutate(message: dict, rng: random.Random, rate: float) -> dict:
    """A copy of `message` with each field (nested ones too) made hostile at `rate`."""
    out = {}
    for field, value in message.items():
        if isinstance(value, dict) and field not in ('stamp', 'mission_start'):
            out[field] = mutate(value, rng, rate)
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            items = [mutate(item, rng, rate) for item in value]
            if rng.random() < rate:
                items = items * 2 if rng.random() < 0.5 else items[:1]
            out[field] = items
        else:
            out[field] = hostile(value, field, rng) if rng.random() < rate else value
    return out


def record_hostile(path, seed: int) -> None:
    rng = random.Random(seed)
    rate = rng.choice((0.05, 0.2, 0.6))
    writer = RecordingWriter(path, chunk_size=4096)
    channels, encoders = {}, {}
    for kind, (topic, name) in TOPICS.items():
        type_name = f'fjsp_msgs/msg/{name}'
        definition = message_definition(type_name, READ_MSG)
        channels[kind] = writer.add_topic(topic, type_name, definition,
                                          Offer(reliable=True, transient_local=True, depth=1))
        encoders[kind] = serialize_dynamic(type_name, definition)[type_name]
    for fact in faulty_mission():
        message = as_message(fact)
        if rng.random() < 0.5:
            message = mutate(message, rng, rate)
        writer.write(channels[type(fact)], encoders[type(fact)](message), 1)
    writer.close()


FOUND = (443811702,)
"""Seeds that once failed: a work bar from t=-1e6, drawn whole, took the renderer for ever."""


@pytest.mark.parametrize('seed', [*range(8), *FOUND, *generated_seeds.fresh(4, salt=7)])
def test_replay_survives_hostile_field_values(tmp_path, seed, capsys):
    path = tmp_path / 'hostile.mcap'
    record_hostile(path, seed)
    assert main([str(path), '--out', str(tmp_path)]) in (0, 1)
    capsys.readouterr()


def retyped(type_name: str, changes: dict[str, str]) -> str:
    """The definition of `type_name` with some fields given other types."""
    text = message_definition(type_name, READ_MSG)
    for field, new_type in changes.items():
        text = re.sub(rf'^\S+(\s+{field}\b)', rf'{new_type}\1', text, count=1, flags=re.M)
    return text


def test_replay_survives_fields_of_the_wrong_type(tmp_path, capsys):
    """The recording's own schema says what each field is: a forged one can make a time a
    string, a name a number, a count a list."""
    path = tmp_path / 'retyped.mcap'
    writer = RecordingWriter(path)
    facts = faulty_mission()
    plan_type, event_type = 'fjsp_msgs/msg/Plan', 'fjsp_msgs/msg/TaskEvent'
    plan_definition = retyped(plan_type, {'time_scale': 'string', 'scenario_id': 'float64'})
    event_definition = retyped(event_type, {'time': 'string', 'job': 'int32',
                                            'plan_revision': 'float64[]', 'kind': 'string'})
    plan_channel = writer.add_topic('/plan', plan_type, plan_definition,
                                    Offer(reliable=True, transient_local=True, depth=1))
    event_channel = writer.add_topic('/task_events', event_type, event_definition,
                                     Offer(reliable=True, transient_local=True, depth=1))
    encode_plan = serialize_dynamic(plan_type, plan_definition)[plan_type]
    encode_event = serialize_dynamic(event_type, event_definition)[event_type]
    plan = as_message(facts[0]) | {'time_scale': 'fast', 'scenario_id': 1.5}
    writer.write(plan_channel, encode_plan(plan), 1)
    event = as_message(facts[2]) | {'time': 'soon', 'job': 7, 'plan_revision': [1.0],
                                    'kind': 'done'}
    writer.write(event_channel, encode_event(event), 2)
    writer.close()
    assert main([str(path), '--out', str(tmp_path)]) == 1
    out = capsys.readouterr().out
    assert '/plan: 1 message(s) could not be read' in out
    assert '/task_events: 1 message(s) could not be read' in out
