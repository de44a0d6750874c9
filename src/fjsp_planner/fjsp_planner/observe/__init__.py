"""What happened in a mission, told from the fleet's topics alone, without ROS.

The monitor node feeds live messages into a `history.FleetHistory`; the `replay` command feeds
the same history from an MCAP recording. Both then show the same things: the terminal frames
and story lines (`text`), the whole-mission Gantt chart (`gantt`), and the live web page
(`dashboard`, `views`). Keeping this free of rclpy is what lets a recording be read back on a
machine with no ROS at all, and lets the history be tested on hand-made message sequences.
"""
