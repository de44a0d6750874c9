"""Lower bounds on the makespan, each sound for any schedule (docs/solver.md, "Bounds").

- `geometry`: least distances along the distance table and the least travel they force
  (one shortest-path routine for every bound and the mission tracker);
- `jobs`: staffings, precedence order, heads and tails, and the critical path bound;
- `fleet`: bounds for any scenario from what the fleet must do: chains from the robots'
  arrival, energy over capability groups, a robot alone with its travel;
- `assignment`: the "fleet load" bound for any scenario, each robot's work and travel
  with the staffing of every job chosen by CP-SAT;
- `restricted`: bounds from sets of jobs, each solved by CP-SAT as a scenario of its own
  with heads and tails; the sets of `chains` (the "chain" bound: the longest precedence
  chains) and of `operations` (the "operation set" bound: the jobs that need one operation
  type);
- `panel`: the panel decomposition bounds for identical panels (energy, clique) and the
  panel limits of robots slow to move between panels;
- `machine`: the "panel machine" relaxation CP-SAT solves to optimality;
- `load`: the "panel load" bound from what each robot must do and travel;
- `sequence`: the "panel sequence" search, which knows where each panel lies.
"""
