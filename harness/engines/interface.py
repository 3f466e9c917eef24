"""harness/engines/interface.py -- the adapter interface (harness/engines/__init__.py, docs/engines.md):
Engine's four methods, a Plan of Features, and the message of a run that cannot be made."""
from dataclasses import dataclass, field

EXACT, APPROXIMATE, REFUSED = "exact", "approximate", "refused"


@dataclass(frozen=True)
class Feature:
    """One feature of a scene and how an engine expresses it.

    name: what the scene uses ('normal law: power, nu = 1.5', 'global damping alpha = 8');
    status: EXACT, APPROXIMATE or REFUSED; how: the mapping (or why it is refused)."""
    name: str
    status: str
    how: str

    def line(self):
        return f"{self.name}: {self.status}: {self.how}"


@dataclass
class Plan:
    """How an engine expresses one scene: a Feature per feature, and the probe columns (or
    run.json fields read by expression functions) it cannot give, {name: why}."""
    features: list = field(default_factory=list)
    unexpressible: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)     # the adapter's own choices (styles, types)

    def add(self, name, status, how):
        self.features.append(Feature(name, status, how))

    def refused(self):
        return [f for f in self.features if f.status == REFUSED]

    def approximate(self):
        return [f for f in self.features if f.status == APPROXIMATE]


class Engine:
    """The adapter interface (the module docstring); name is the word of the run's command
    (ENGINE:COMMAND, e.g. lammps:run), title what reports call the engine."""
    name = ""
    title = ""

    def problem(self):
        raise NotImplementedError

    def identity(self):
        raise NotImplementedError

    def version(self):
        return ""

    def plan(self, scene, command):
        raise NotImplementedError

    def simulate(self, scene, plan, work):
        raise NotImplementedError


def not_expressible_message(engine, plan):
    """The one-line reason a run could not be made: every refused feature."""
    refused = plan.refused()
    return f"not expressible in {engine.title}: " + "; ".join(f"{f.name}: {f.how}" for f in refused)
