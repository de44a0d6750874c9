"""Lower bounds on the makespan, each sound for any schedule (docs/solver.md, "Bounds").

- `panel`: the critical path, and the panel decomposition bounds for identical panels
  (energy, clique), with the geometry the others share (least travel, panel limits);
- `machine`: the "panel machine" relaxation CP-SAT solves to optimality;
- `load`: the "panel load" bound from what each robot must do and travel;
- `sequence`: the "panel sequence" search, which knows where each panel lies.
"""
