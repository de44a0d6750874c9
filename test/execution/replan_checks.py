"""What every re-plan must satisfy, whatever the solver's choices."""


def check_replan_result(state, result):
    """`result` (a `Replan` of `state`) is valid, gives the failed robots nothing, redoes only
    the jobs it voided or keeps, keeps those as posed, and starts nothing new before now."""
    assert result.problems == []
    schedule = result.schedule
    failed = {name for name, r in state.robots.items() if not r.healthy}
    assert not failed & set().union(*(a.robots for a in schedule.jobs.values()))
    assert all(not schedule.sequences.get(name) for name in failed)
    # Finished jobs are not redone; a kept jig job stays exactly as it was posed.
    redone = state.done & set(schedule.jobs)
    assert redone == set(result.residual.kept) | set(result.residual.voided)
    for name in result.residual.kept:
        fixed = result.residual.problem.fixed[name]
        assert (schedule.jobs[name].start, schedule.jobs[name].end) == (fixed.start, fixed.end)
    assert all(a.start >= state.now for name, a in schedule.jobs.items()
               if name not in result.residual.problem.fixed)
    return result
