"""What happened in a mission, told from the fleet's topics alone, without ROS.

The monitor node feeds live messages into a `history.FleetHistory` (through `facts`); the
`replay` command feeds the same history from an MCAP recording (`recording`). Both then show
the same things (`views`): the story of each mission (`story`), the terminal frames and lines
(`text`), the whole-mission Gantt chart (`mission_chart`), the robots on the mission's map
(`fleet_map`) and the live web page (`dashboard`). `plan_chart` draws one schedule
(`fjsp-solve --gantt`); `chart_layout` keeps both charts readable however large the mission.
Keeping this free of rclpy is what lets a recording be read back on a machine with no ROS at
all, and lets the history be tested on hand-made message sequences.
"""
