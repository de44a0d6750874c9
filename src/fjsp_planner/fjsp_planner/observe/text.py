"""The terminal monitor's words: a frame of the mission whenever something a person would
notice changed, one line per event of the story, and the summary of an ended mission, so that
a scroll-back of the monitor's output tells what happened and why."""

from fjsp_common.decimals import decimal, decimals
from fjsp_planner.observe.history import MissionHistory


def frame(header: dict | None, rows: list[dict]) -> tuple[str, tuple]:
    """The frame's text, and its key: what a new frame must differ in to be printed. The key
    leaves out what moves all the time (the clock, progress, the projected makespan). With
    no mission (`header` None) it shows the robots that reported."""
    h = header
    if h is None:
        lines = ['no mission yet (is the planner running?)']
        key = ()
    else:
        lines = [
            f"mission {h['mission_id']} ({h['scenario']}), revision {h['revision']}: "
            f"{h['state']}, {h['jobs_done']}/{h['jobs_total']} jobs done, {h['jobs_running']} "
            'running; makespan planned {}, projected {}'.format(
                *decimals(h['planned_makespan'], h['projected_makespan']))
            + f"; t={decimal(h['time'])}"]
        if any(h['ignored']):
            stale, duplicate, unknown = h['ignored']
            lines[0] += f'; ignored {stale} stale, {duplicate} duplicate, {unknown} unknown'
        if h['revision'] > 1 and h['replan_reasons']:
            lines.append(f"  re-planned because: {'; '.join(h['replan_reasons'])}")
        lines += [f'  warning: {w}' for w in h['warnings']]
        lines += [f"  {h['reasons_label'].lower()}: {b}" for b in h['blocked_reasons']]
        key = (h['mission_id'], h['state'], h['revision'], h['jobs_done'], h['jobs_running'],
               h['jobs_total'], tuple(h['replan_reasons']), tuple(h['warnings']),
               tuple(h['blocked_reasons']), tuple(h['ignored']))
    lines += ['  ' + robot_line(row) for row in rows]
    key += tuple((r['robot'], r['mode'], r.get('job'), r.get('location'),
                  r.get('destination'), r.get('detail')) for r in rows)
    return '\n'.join(lines), key


def robot_line(row: dict) -> str:
    name, mode = row['robot'], row['mode']
    if 'job' not in row:
        return f'{name:<10} {mode}'
    busy = mode in ('travelling', 'working')
    progress = f"{row['progress']:4.0%}" if busy and row['progress'] is not None else '    '
    where = (f"{row['location'] or '?'} -> {row['destination']}" if row['destination']
             else row['location'] or '-')
    line = f"{name:<10} {mode:<10} job {row['job'] or '-':<6} {progress}  at {where}"
    if row['detail']:
        line += f"; {row['detail']}"
    elif not row['healthy'] and row['since'] is not None:
        line += f"; since t={decimal(row['since'])}"
    return line


def story_line(item: dict) -> str:
    return f"t={decimal(item['time']):>8}  {item['text']}"


def summary(mission: MissionHistory) -> str:
    """One paragraph on an ended (or abandoned) mission: counts, makespans, revisions."""
    counts = mission.counts()
    status = mission.status
    revisions = mission.revisions()
    state = status.state if status else 'unknown'
    shown = [r for r in revisions if r.makespan == r.makespan]
    executed, *makespans = decimals(mission.executed_makespan(), *(r.makespan for r in shown))
    planned = ', '.join(f'{m} in revision {r.number}' for m, r in zip(makespans, shown,
                                                                     strict=True))
    text = (f'mission {mission.mission_id} ({mission.scenario_id}) {state}: '
            f'{counts.done}/{counts.total} jobs done')
    if status is not None:
        text += (f' (planner: {status.jobs_done}/{status.jobs_total}'
                 + ('' if mission.agrees_with_status() else ', DISAGREES') + ')')
    text += (f'; {len(revisions)} revision{"s" if len(revisions) != 1 else ""}, '
             f'{counts.aborted} aborted attempt{"s" if counts.aborted != 1 else ""}, '
             f'{counts.voided} voided; makespan executed {executed}')
    if planned:
        text += f', planned {planned}'
    return text
