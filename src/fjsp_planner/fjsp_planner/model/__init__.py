"""The scheduling problem and its answers, without ROS or solvers (docs/model.md).

- `problem`: `Problem` and its parts, plain immutable data checked at construction;
- `scenario`: YAML scenario files (docs/scenario-format.md) and N-panel repetition;
- `fjs`: the classic FJSP benchmark text format;
- `places`: locations on a map, and the Euclidean distances their coordinates imply;
- `extension`: jobs added to a running mission, as a scenario fragment;
- `limits`: how large and how extreme an input may be, checked before anything is built;
- `schedule`: `Schedule` (exact times) and the solver-neutral `Result`;
- `validate`: the independent check every schedule goes through; it shares no code with the
  solvers. Its messages (`Violation`) read in decimals (`fjsp_common.decimals`) and keep
  the exact times.
"""
