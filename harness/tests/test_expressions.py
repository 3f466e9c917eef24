"""The registry of expression functions (harness/expressions.py): the families register into
it, compare.py asks it and knows no family."""
import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from harness import expressions
from harness.compare import evaluate, namespace
from harness.errors import EvalError
from harness.tables import Run

HARNESS = Path(__file__).resolve().parents[1]

# Every function name an expression could call before the families had modules of their own.
NAMES_BEFORE = {"first", "last", "mean", "max", "min", "std", "amp", "abs", "sqrt", "at", "after", "upto",
                "between", "period", "settle", "run", "energy", "series", "pile_X", "pile_S", "middle",
                "horizontal_contacts", "contact_error", "contact_mismatch", "weight", "contact_start",
                "contact_end", "sine_period", "sine_amplitude", "contact_duration", "restitution", "of", "order"}
# ... and those a family has added since, from its own module.
NAMES_ADDED = {"fit_slope"}             # rolling: the law tester (cases/rolling)
# The names issue 21 added: spread (variants) and the biaxial family (JYH 2005).
BIAXIAL = {"spread", "sigma_v", "sigma_h", "mean_stress", "deviator", "phi", "axial_strain", "lateral_strain",
           "volumetric_strain", "shear_start", "phi_peak", "peak_cycle", "at_peak", "phi_residual",
           "window_mean", "residual_drift", "dilation", "phi_envelope", "cohesion_envelope", "setting"}
ENSEMBLES = {"members", "seeds", "realisations", "over"}   # issue 22: over an [ensemble]'s realisations
# issue 21's case: the planar void ratio of a specimen and its profile over height (biaxial)
VOID_RATIO = {"void_ratio", "void_ratios", "band_heights", "initial_void_ratio"}
# issue 22: the statistics of polydisperse piles over an ensemble (families/pile_stats.py)
PILE_STATS = {"ens_X", "ens_S", "ens_S_se", "dip", "dip_se", "profile_dip", "coordination", "ens_forces",
              "tail_rate", "tail_ks", "ens_fluct", "ens_rho", "log10"}
# issue 30: the Coulomb cap at the sliding contacts of a final state (families/coulomb.py)
COULOMB = {"coulomb_error", "sliding_contacts"}
# issue 33: the rate study (biaxial, over ensembles of specimens) and the ensemble's size (pile_stats)
STUDIES = {"strain_rate", "fastest_within", "sd", "this_ensemble", "same_seed", "paired", "means", "paired_means",
           "dip_first", "dip_se_first", "dip_se_blocks", "dip_sd_blocks", "dip_mean_blocks", "se_exponent", "n_for_z"}
NAMES = NAMES_BEFORE | NAMES_ADDED | BIAXIAL | ENSEMBLES | VOID_RATIO | PILE_STATS | COULOMB | STUDIES


def _run(**columns):
    cycle = np.arange(8.0)
    cols = {"cycle": cycle, "time": cycle / 4, **{k: np.asarray(v, dtype=float) for k, v in columns.items()}}
    return Run(folder=None, info={"status": "ok", "dt": 0.25}, columns=cols)


def test_every_family_registered_and_every_name_kept():
    assert list(expressions.registered()) == ["signals", "variants", "piles", "networks", "collisions",
                                              "rolling", "biaxial", "ensembles", "pile_stats", "coulomb"]
    names = {n for n, f in namespace(_run()).items() if callable(f)}
    assert names == NAMES


def test_a_family_function_is_available():
    gap = [1.0, 0.5, -0.25, -0.5, -0.25, 0.5, 1.0, 1.5]    # an elastic collision in the gap column
    assert evaluate("restitution(g)", _run(g=gap)) == pytest.approx(1.0)
    assert evaluate("period(s)", _run(s=[-1, 0, 1, 0, -1, 0, 1, 0])) == 4.0


def test_an_unknown_function_says_so_and_lists_every_function():
    with pytest.raises(EvalError) as caught:
        evaluate("nosuch(F)", _run(F=np.ones(8)))
    message = str(caught.value)
    assert message.startswith("unknown function 'nosuch' (functions: ") and message.endswith(")")
    listed = message[len("unknown function 'nosuch' (functions: "):-1].split(", ")
    assert set(listed) == NAMES and len(listed) == len(NAMES)


def test_a_family_cannot_take_a_name_of_the_language_or_of_another_family():
    with pytest.raises(ValueError, match="'mean' is a function of the expression language itself"):
        expressions.register("test_clash", ("mean",), lambda run, sibling: {})
    with pytest.raises(ValueError, match="'restitution' is already a function of family 'collisions'"):
        expressions.register("test_clash", ("restitution",), lambda run, sibling: {})
    assert "test_clash" not in expressions.registered()


def test_a_new_family_registers_from_its_own_module_and_compare_finds_it():
    expressions.register("test_twice", ("twice",), lambda run, sibling: {"twice": lambda a: 2 * a})
    try:
        assert evaluate("twice(last(F))", _run(F=np.arange(8.0))) == 14.0
    finally:
        expressions._families.pop("test_twice")


def _imports(path):
    """The modules a source file imports, relative ones written as .name / ..name."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = "." * node.level + (node.module or "")
            found += [base] if node.module else [base + a.name for a in node.names]
    return found


def test_compare_imports_no_family():
    imported = _imports(HARNESS / "compare.py")
    assert not [m for m in imported if "families" in m], imported
    assert ".expressions" in imported
    # nor through another module: a fresh interpreter that imports compare has no family loaded
    code = "import sys, harness.compare; print(sorted(m for m in sys.modules if 'families' in m))"
    done = subprocess.run([sys.executable, "-c", code], cwd=HARNESS.parent, capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.strip() == "[]", done.stderr
