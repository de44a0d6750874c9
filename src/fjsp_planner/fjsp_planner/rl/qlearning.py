"""Tabular Q-learning (paper eq. 1) with ε-greedy exploration, seeded for repeatability.

Q(s, a) <- Q(s, a) + α [r + γ max_a' Q(s', a') - Q(s, a)], with γ = 0.4 and α = 0.5 as the
paper chose after its grid search; a terminal step (schedule complete or a violation) has no
future term. ε decays geometrically from `epsilon_start` to `epsilon_end` over the episodes,
the paper does not give its schedule. The table starts at 0, above every return (all rewards
are negative), so untried actions look best and get tried.
"""

from dataclasses import dataclass, field

import numpy as np

from fjsp_planner.model.schedule import Schedule


@dataclass
class Training:
    q: np.ndarray
    returns: list[float] = field(default_factory=list)
    """Undiscounted return of each training episode."""
    completed: list[bool] = field(default_factory=list)
    """Whether each training episode built a whole schedule without a violation."""


def train(env, episodes: int = 20_000, alpha: float = 0.5, gamma: float = 0.4,
          epsilon_start: float = 1.0, epsilon_end: float = 0.02, seed: int = 0) -> Training:
    """Learn a Q-table on `env` (any env with Discrete observations and actions)."""
    rng = np.random.default_rng(seed)
    n_states, n_actions = env.observation_space.n, env.action_space.n
    result = Training(np.zeros((n_states, n_actions)))
    q = result.q
    decay = (epsilon_end / epsilon_start) ** (1 / max(1, episodes - 1))
    epsilon = epsilon_start
    for episode in range(episodes):
        state, _ = env.reset(seed=seed + episode)
        total, done, info = 0.0, False, {}
        while not done:
            if rng.random() < epsilon:
                action = int(rng.integers(n_actions))
            else:
                action = _argmax(q[state], rng)
            following, reward, terminated, truncated, info = env.step(action)
            done = terminated or truncated
            future = 0.0 if terminated else gamma * q[following].max()
            q[state, action] += alpha * (reward + future - q[state, action])
            state, total = following, total + reward
        result.returns.append(total)
        result.completed.append('schedule' in info)
        epsilon *= decay
    return result


def greedy_rollout(env, q: np.ndarray) -> tuple[Schedule | None, str | None]:
    """Follow the table greedily once: the schedule built, or None and the violation."""
    state, _ = env.reset()
    for _ in range(env.action_space.n + 1):
        state, _, terminated, truncated, info = env.step(int(np.argmax(q[state])))
        if 'schedule' in info:
            return info['schedule'], None
        if terminated or truncated:
            return None, info.get('violation', 'episode ended')
    return None, 'greedy policy did not finish'


def _argmax(values: np.ndarray, rng) -> int:
    """Greedy action, ties broken at random so equal untried actions all get a turn."""
    best = np.flatnonzero(values == values.max())
    return int(rng.choice(best))
