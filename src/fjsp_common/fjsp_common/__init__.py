"""The fleet's shared contract: what the planner, the robot agents and any monitor agree on.

Free of ROS, so the domain core and tools use them too:

- `vocabulary`: robot modes, event kinds and mission states, named once;
- `fleet`: node names and the defaults the whole fleet shares (heartbeat period and timeout);
- `clock`: one mission's schedule clock, wall seconds <-> schedule units;
- `revisions`: which attempt at a job a report is about, and whether it still counts;
- `parameters`: a node parameter's one definition (`ParameterSpec`);
- `decimals`: how every time a person reads is written (decimals, never raw fractions);
- `bounded_yaml`: YAML read within limits of nesting, values and size, checked before
  PyYAML builds anything (every YAML input of the project goes through it);
- `wellformed`: what a plan or event must hold to be acted on (times that are numbers, a
  usable time scale), checked by every reader.

With ROS:

- `contract`: the topic table (names, message types, QoS) and the vocabularies paired with
  the message constants;
- `running`: how every node declares its parameters and runs;
- `auth`: the fleet key, signing and checking;
- `diagnostics`: health on `/diagnostics`.
- `ros2cli`: the workspace's `ros2` front end (node, param, service, action, topic and
  interface verbs), a stand-in for ros2cli where it is not installed.
"""
