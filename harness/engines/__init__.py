"""harness/engines: other DEM engines through ballast's catalogue (docs/engines.md).

An engine adapter takes a case's scene, with the variant's --set lines and command, and
either makes the run in its engine and brings it back in ballast's output formats
(series.tsv, discs.tsv, contacts.tsv, walls.tsv, stress.tsv, run.json), so that the case's
own checks and references (reference/*.ref, harness/compare.py) apply unchanged, or says,
feature by feature, what of the scene its engine cannot express.  A run it cannot make is
written as run.json with status 'not_expressible' and the reasons; every check that reads
it is then "not expressible in ENGINE" (compare.py), never a pass, a fail or a skip.

The interface (Engine, interface.py) is four methods:

    problem()            why the engine cannot run at all ('' when it can): not installed,
                         missing styles; installing it first where the adapter knows how
    identity()           what decides its outputs besides the scene: its executable and the
                         adapter's own files (runner.identity: --resume reruns on a change)
    plan(scene, command) a Plan: one Feature per scene feature, each 'exact' (the same
                         discrete equations, to round-off), 'approximate' (the same physics, a
                         stated difference) or 'refused' (not expressible, with why)
    simulate(scene, plan, work)
                         the run, as a Trajectory (harness/engines/trajectory.py): the
                         state at every output row and at the end, contacts and walls
                         included, each engine's quantities in ballast's conventions

and make_run() (driver.py) does the rest the same for every engine: the scene read and its
initial state from the core (scene.py), the plan, and either the not-expressible run.json or
the trajectory turned into ballast's files (outputs.py).

Adapters: lammps.py (Debian's `lammps`).  docs/engines.md says what a LIGGGHTS or YADE
adapter would need.
"""
