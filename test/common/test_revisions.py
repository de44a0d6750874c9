"""The attempt-revision rule every receiver of plans and reports judges by, checked by hand."""

from types import SimpleNamespace

from fjsp_common.revisions import Restarts, attempt_revision, plan_attempts, void


def task(job, continued, restarted_in):
    return SimpleNamespace(job=job, continued=continued, restarted_in=restarted_in)


def test_a_task_starting_its_job_afresh_begins_an_attempt_of_its_own_revision():
    assert attempt_revision(4, continued=False, restarted_in=2) == 4


def test_a_continued_task_goes_on_with_the_attempt_it_names_never_a_later_one():
    assert attempt_revision(4, continued=True, restarted_in=2) == 2
    assert attempt_revision(4, continued=True, restarted_in=9) == 4
    assert attempt_revision(4, continued=True, restarted_in=0) == 0  # the plan does not say


def test_reports_under_an_older_revision_than_the_restart_are_void():
    assert void(2, restarted_in=3)
    assert not void(3, restarted_in=3)
    assert not void(5, restarted_in=3)


def test_a_plan_gives_each_job_the_attempt_its_tasks_name():
    tasks = [task('Ja', False, 0), task('Ja', False, 0), task('Aa', True, 2),
             task('Jb', True, 0)]
    assert plan_attempts(3, tasks) == {'Ja': 3, 'Aa': 2, 'Jb': 0}


def test_restarts_keep_the_latest_whatever_order_plans_come_in():
    restarts = Restarts()
    assert restarts.latest('Ja') == 0 and not restarts.void('Ja', 0)
    assert restarts.restart('Ja', 3)
    assert not restarts.restart('Ja', 2)  # an older plan received late changes nothing
    assert restarts.latest('Ja') == 3
    assert restarts.void('Ja', 2) and not restarts.void('Ja', 3)
    assert not restarts.void('Aa', 1)
