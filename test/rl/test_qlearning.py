"""The RL environment (paper §V, §VI-B) and tabular Q-learning, on tiny instances."""

from fractions import Fraction

import gymnasium
import pytest

from fjsp_planner.model.problem import Job, Problem, Robot
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.model.validate import validate
from fjsp_planner.rl import ENV_ID
from fjsp_planner.rl.env import PENALTY, AssemblyEnv, restrict
from fjsp_planner.rl.qlearning import greedy_rollout, train

from repo_paths import PAPER


@pytest.fixture
def tiny():
    """a (hold) -> b (hold + weld), a held into b; c (weld) is free.

    Optimum 2: R1 holds in a [0, 1] and b [1, 2], R2 welds c [0, 1] and b [1, 2].
    """
    return Problem(
        operation_types={0: 'hold', 1: 'weld'},
        robot_types={'A': {0: Fraction(1), 1: Fraction(2)},
                     'B': {0: Fraction(2), 1: Fraction(1)}},
        robots=(Robot('R1', 'A'), Robot('R2', 'B')),
        jobs=(Job('a', 'x', ((0,),)), Job('b', 'x', ((0, 1),)), Job('c', 'x', ((1,),))),
        precedence=(('a', 'b'),),
        holding=(('a', 'b', 0),),
    )


def action(env, job, robots):
    """The action doing `job` with robots[o] on operation o."""
    for a in range(env.action_space.n):
        name, assignment = env.decode(a)
        if name == job and assignment.robots == tuple(robots):
            return a
    raise AssertionError(f'no action for {job} {robots}')


def test_registered_env_has_the_paper_state_and_action_counts():
    subset = restrict(load_scenario(PAPER), ['M2', 'Ja', 'Aa', 'Jb', 'Ab'])
    env = gymnasium.make(ENV_ID, problem=subset)
    # 5 jobs × 4! robot orderings = 120 (job, assignment) states and actions, + start state.
    assert env.action_space.n == 120
    assert env.observation_space.n == 121
    # Without repeats: a welder (4 ways) and an unordered pair of holders of the other 3 (3).
    assert len(AssemblyEnv(subset, assignments='distinct').options['Aa']) == 12


def test_rewards_are_minus_the_makespan_increase(tiny):
    env = AssemblyEnv(tiny)
    assert env.reset(seed=1) == (0, {})
    state, reward, done, truncated, _ = env.step(action(env, 'a', ['R1']))
    assert (reward, done, truncated) == (-1.0, False, False)
    assert state == 1 + action(env, 'a', ['R1'])
    _, reward, done, _, _ = env.step(action(env, 'c', ['R2']))
    assert (reward, done) == (0.0, False)  # c fits beside a
    _, reward, done, _, info = env.step(action(env, 'b', ['R1', 'R2']))
    assert (reward, done) == (-1.0, True)
    assert info['schedule'].makespan == 2
    assert validate(tiny, info['schedule']) == []


@pytest.mark.parametrize(('steps', 'reason'), [
    ([('b', ['R1', 'R2'])], "precedence: job 'b' before its predecessor 'a'"),
    ([('a', ['R1']), ('a', ['R2'])], "job 'a' is already done"),
    ([('a', ['R1']), ('c', ['R1'])], "robot 'R1' must go to 'b' before 'c'"),
    ([('a', ['R1']), ('b', ['R2', 'R1'])], "type-0 robots of 'a' are ['R1']"),
])
def test_violations_cost_the_penalty_and_end_the_episode(tiny, steps, reason):
    env = AssemblyEnv(tiny)
    env.reset()
    for job, robots in steps:
        _, reward, done, _, info = env.step(action(env, job, robots))
    assert (reward, done) == (-PENALTY, True)
    assert reason in info['violation']


def test_trained_agent_returns_a_valid_schedule(tiny):
    env = gymnasium.make(ENV_ID, problem=tiny)
    training = train(env, episodes=400, seed=3)
    schedule, violation = greedy_rollout(env, training.q)
    assert violation is None
    assert validate(tiny, schedule) == []
    assert set(schedule.jobs) == {'a', 'b', 'c'}
    assert len(training.returns) == 400


def test_bad_arguments_are_named(tiny):
    with pytest.raises(ValueError, match="unknown assignment mode 'all'"):
        AssemblyEnv(tiny, assignments='all')
    with pytest.raises(ValueError, match=r"has no job\(s\) \['zz'\]"):
        restrict(tiny, ['a', 'zz'])
