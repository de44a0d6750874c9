"""The launcher: one fleet's processes from start-up to the end of its mission.

- `supervision`: `Fleet`, the processes of one fleet (planner, one agent per robot, monitor,
  recorder), each in a process group of its own, stopped together, started again on demand;
- `respawn`: when a node that ended is started again, and when the launcher gives up on it
  (no ROS, no processes: tested on a fake clock);
- `params`: the user's ROS parameters file and the per-node files the launcher writes;
- `listener`: a private rclpy node on a thread of its own, through which the launcher (and
  the test harness) hears the fleet's topics;
- `status`: which mission statuses the launcher believes: signed by its planner, about the
  mission that planner runs;
- `cli`: `ros2 run fjsp_planner fleet`, which keeps the fleet's nodes running, judges the
  mission from `mission_status` and exits with its outcome;
- `hosts`: simulated hosts on network namespaces, for running a fleet across real links.

`launch` and `launch_ros` are not published on PyPI, so this is the project's one launcher,
used alike by `ros2 run fjsp_planner fleet`, `ros2_ws/demo.sh`, the test harness
(`fjsp_planner.testing`) and the benchmarks.
"""
