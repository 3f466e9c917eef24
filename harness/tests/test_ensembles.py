"""[ensemble NAME] in case.txt (harness/ensembles.py): one variant per seed, NAME_s<seed>,
validated with file:line; the expression functions over an ensemble (families/ensembles.py);
`list` shows it in a few words; the stability finder takes its first realisation only."""
import numpy as np
import pytest

from harness import catalogue, stability
from harness.__main__ import main
from harness.compare import RunStore, folder_locator, quantity_in
from harness.ensembles import parse_seeds, seeds_text
from harness.errors import EvalError, IniError
from harness.tests.test_catalogue import CASE, write

ENSEMBLE = """
[ensemble poly]
scene = s.scene
set = a.b=2
set = fill.p.seed={seed}
seeds = 3-5 9
"""


@pytest.mark.parametrize("text, seeds", [
    ("1-100", list(range(1, 101))), ("7", [7]), ("1 2 5", [1, 2, 5]), ("1-3, 10 20-21", [1, 2, 3, 10, 20, 21]),
    ("0-2", [0, 1, 2]), ("007", [7]), ("5 1", [5, 1])])
def test_seeds(text, seeds):
    assert parse_seeds(text) == seeds


@pytest.mark.parametrize("text, words", [
    ("", "no seeds"), ("1-", "not a seed"), ("-3", "not a seed"), ("a", "not a seed"), ("1.5", "not a seed"),
    ("5-3", "runs backwards"), ("1-3 2", "seed 2 is given twice"), ("0-100000", "more than 100000")])
def test_bad_seeds(text, words):
    with pytest.raises(ValueError, match=words):
        parse_seeds(text)


def test_seeds_text_collapses_runs():
    assert seeds_text([1, 2, 3, 7, 9, 10]) == "1-3 7 9-10"
    assert seeds_text(parse_seeds("1-300")) == "1-300"


def test_an_ensemble_is_one_variant_per_seed(tmp_path):
    write(tmp_path, "fam", CASE + ENSEMBLE + "[variant after]\nscene = s.scene\n")
    case = catalogue.load(tmp_path)[0]
    assert case.variant_names() == ["v1", "v2", "poly_s3", "poly_s4", "poly_s5", "poly_s9", "after"]
    v = case.variant("poly_s4")
    assert (v.scene, v.sets, v.command, v.ensemble, v.seed) == (
        tmp_path / "fam" / "s.scene", ["a.b=2", "fill.p.seed=4"], "run", "poly", 4)
    assert case.variant("v1").ensemble == "" and case.variant("v1").seed is None
    assert case.ensemble_members() == {"poly": ["poly_s3", "poly_s4", "poly_s5", "poly_s9"]}
    assert case.variant_summary() == "v1 v2 poly_s[3-5 9] after"
    assert catalogue.ensembles_of([case]) == {"c1": case.ensemble_members()}


def test_seed_in_the_scene_and_an_exact_ensemble(tmp_path):
    write(tmp_path, "fam", CASE + "[ensemble pre]\nscene = pile_{seed}.scene\nseeds = 1 2\ncommand = exact\n")
    case = catalogue.load(tmp_path)[0]
    assert [(v.name, v.scene.name, v.sets, v.command) for v in case.variants[2:]] == [
        ("pre_s1", "pile_1.scene", [], "exact"), ("pre_s2", "pile_2.scene", [], "exact")]


def test_a_figure_may_name_an_ensemble(tmp_path):
    write(tmp_path, "fam", CASE + ENSEMBLE + "[figure f]\nx = cycle\ny = A\nvariants = v1 poly\n")
    assert catalogue.load(tmp_path)[0].figures[0].variants == ["v1", "poly_s3", "poly_s4", "poly_s5", "poly_s9"]


ERRORS = [
    (ENSEMBLE.replace("fill.p.seed={seed}", "fill.p.seed=1"), 14, "uses {seed} nowhere"),
    (ENSEMBLE.replace("{seed}", "{sed}"), 17, "'{sed}' is not a placeholder"),
    (ENSEMBLE.replace("=2", "={seed"), 16, "'{' is not a placeholder"),
    (ENSEMBLE.replace("3-5 9", "3-5 4"), 18, "seeds: seed 4 is given twice"),
    (ENSEMBLE.replace("seeds = 3-5 9\n", ""), 14, "needs 'seeds = ...'"),
    (ENSEMBLE.replace("a.b=2", "nokeyvalue"), 16, "needs KEY=VALUE"),
    (ENSEMBLE + "command = peer\n", 19, "must be one of run, exact"),
    (ENSEMBLE + "sets = x\n", 19, "unknown key 'sets'"),
    (ENSEMBLE + "[variant poly_s4]\nscene = s\n", 19, "keeps for its realisations"),
    (ENSEMBLE + "[variant poly_s400]\nscene = s\n", 19, "keeps for its realisations"),
    (ENSEMBLE + "[variant poly]\nscene = s\n", 19, "already the name of ensemble 'poly'"),
    (ENSEMBLE + ENSEMBLE, 20, "already the name of ensemble 'poly'"),
    (ENSEMBLE.replace("[ensemble poly]", "[ensemble v1]"), 14, "the case already has a variant 'v1'"),
    ("[variant poly_s7]\nscene = s\n" + ENSEMBLE, 16, "the case already has a variant 'poly_s7'"),
    (ENSEMBLE + "[figure n]\nkind = network\nvariants = poly\n", 19, "exactly one variant, not the 4"),
]


@pytest.mark.parametrize("extra, line, words", ERRORS, ids=[
    "no-placeholder", "other-placeholder", "lone-brace", "seed-twice", "no-seeds", "set", "command", "key",
    "variant-claimed", "variant-claimed-any-seed", "variant-named-as-ensemble", "ensemble-twice",
    "ensemble-named-as-variant", "ensemble-claims-variant", "network-of-ensemble"])
def test_errors_name_file_and_line(tmp_path, extra, line, words):
    write(tmp_path, "fam", CASE + extra)
    with pytest.raises(IniError) as err:
        catalogue.load(tmp_path)
    assert f"case.txt:{line}:" in str(err.value)
    assert words in str(err.value)


def test_stability_bisects_the_first_realisation_only(tmp_path):
    write(tmp_path, "fam", CASE + ENSEMBLE)
    assert [t.variant for t in stability.targets_for(catalogue.load(tmp_path))] == ["v1", "v2", "poly_s3"]


# ---------------------------------------------------------------- over an ensemble (fake core)

def add_ensemble(project, text):
    path = project / "cases" / "springs" / "case.txt"
    path.write_text(path.read_text() + text)


SPRINGS = "\n[ensemble k]\nscene = spring.scene\nset = k={seed}\nseeds = 1-4\n"


def test_the_expression_functions_over_an_ensemble(project, runs, capsys):
    add_ensemble(project, SPRINGS)
    assert main(["run", "spring"]) == 0
    assert "[7/7] spring/" in capsys.readouterr().out
    cases = catalogue.load()
    store = RunStore(folder_locator(runs), catalogue.ensembles_of(cases))
    q = lambda expr, variant="soft": quantity_in(store, "spring", variant, expr)
    assert q("mean(over('k', 'last(F)'))") == 25.0              # F = k x 10, k = 1..4
    assert q("std(over('k', 'last(F)'))") == pytest.approx(11.180339887498949)
    assert q("realisations('k')") == 4.0 and q("max(seeds('k'))") == 4.0
    assert q("mean([of(v, 'last(F)') for v in members('k')])", "k_s2") == 25.0
    assert q("last(F) - mean(over('k', 'last(F)'))", "k_s4") == 15.0
    with pytest.raises(EvalError, match="no ensemble 'q' \\(has: k\\)"):
        q("mean(over('q', 'last(F)'))")
    with pytest.raises(EvalError, match="over\\(\\): realisation 'k_s1': .*column 'G' missing"):
        q("mean(over('k', 'last(G)'))")
    (runs / "spring" / "k_s3" / "run.json").unlink()
    fresh = RunStore(folder_locator(runs), catalogue.ensembles_of(cases))
    with pytest.raises(EvalError, match="over\\(\\): variant 'k_s3': run.json missing"):
        quantity_in(fresh, "spring", "soft", "mean(over('k', 'last(F)'))")
    without = RunStore(folder_locator(runs))           # no catalogue: said, not guessed
    with pytest.raises(EvalError, match="no ensembles are known here"):
        quantity_in(without, "spring", "soft", "mean(over('k', 'last(F)'))")


def test_a_check_over_an_ensemble_through_the_command_line(project, runs, capsys):
    add_ensemble(project, SPRINGS)
    ref = project / "reference" / "springs.ref"
    ref.write_text(ref.read_text() + "\n[check k_mean]\ncase = spring\nvariant = k_s1\n"
                   "quantity = mean(over('k', 'last(F)'))\nvalue = 25\ntolerance = abs 0\nkind = analytic\n"
                   "provenance = F = 10 k, k = 1..4\n")
    assert main(["run", "spring"]) == 0
    capsys.readouterr()
    assert main(["check", "-v", "spring"]) == 0
    assert "k_mean" in capsys.readouterr().out


def test_list_shows_an_ensemble_in_a_few_words(project, capsys):
    add_ensemble(project, SPRINGS.replace("1-4", "1-300"))
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert "soft stiff stiffer k_s[1-300]" in out and "k_s17" not in out


# ---------------------------------------------------------------- pairs of ensembles (issue 33)

PAIRS = """
[ensemble k]
scene = spring.scene
set = k={seed}
set = stage.shear.strain_rate=top 1 bottom
seeds = 1-3

[ensemble j]
scene = spring.scene
set = k={seed}.05
set = stage.shear.strain_rate=top 2 bottom
seeds = 1-3

[ensemble i]
scene = spring.scene
set = k={seed}.2
set = stage.shear.strain_rate=top 4 bottom
seeds = 1-3

[ensemble h]
scene = spring.scene
set = k={seed}
set = stage.shear.strain_rate=top 8 bottom
seeds = 1-3

[ensemble odd]
scene = spring.scene
set = k={seed}
set = stage.shear.strain_rate=top 16 bottom
seeds = 1 2 5
"""


def test_paired_ensembles_specimen_by_specimen(project, runs, capsys):
    """F = 10 k at the last row: k = seed in ensemble k, seed + 0.05 in j, seed + 0.2 in i, so
    each realisation of j is 0.5 above its counterpart of the same seed in k, of i 2."""
    add_ensemble(project, PAIRS)
    assert main(["run", "spring"]) == 0
    capsys.readouterr()
    store = RunStore(folder_locator(runs), catalogue.ensembles_of(catalogue.load()))
    q = lambda expr, variant="soft": quantity_in(store, "spring", variant, expr)
    assert q("same_seed('k', 'last(F)')", "j_s2") == pytest.approx(20.0)
    assert q("last(F) - same_seed('k', 'last(F)')", "i_s3") == pytest.approx(2.0)
    assert list(quantity_array(store, "paired('j', 'k', 'last(F)')")) == pytest.approx([0.5] * 3)
    assert list(quantity_array(store, "means(['k', 'j'], 'last(F)')")) == pytest.approx([20.0, 20.5])
    assert list(quantity_array(store, "paired_means(['k', 'j', 'i'], 'k', 'last(F)')")) == pytest.approx([0, 0.5, 2])
    assert q("sd(over('k', 'last(F)'))") == pytest.approx(10.0)             # 10, 20, 30
    assert q("sd([1, 2, 3, 4])") == pytest.approx(np.std([1, 2, 3, 4], ddof=1))
    assert q("log10(mean(over(this_ensemble(), \"run('steps')\")))", "j_s1") == pytest.approx(1.0)
    assert q("strain_rate()", "i_s1") == 4.0
    # the cheapest (fastest) rate within tol of k, at that rate and every slower one: h (8 /s) is
    # back at 0 but i (4 /s) between is 2 off, so within 1 the answer is j's 2 /s
    names = "['k', 'j', 'i', 'h']"
    assert q(f"fastest_within(1, 'last(F)', 'k', {names})") == 2.0
    assert q(f"fastest_within(0.1, 'last(F)', 'k', {names})") == 1.0
    assert q(f"fastest_within(2.5, 'last(F)', 'k', {names})") == 8.0
    with pytest.raises(EvalError, match="no realisation of an ensemble"):
        q("this_ensemble()")
    with pytest.raises(EvalError, match="ensemble 'odd' has no realisation of seed 3"):
        q("same_seed('odd', 'last(F)')", "k_s3")
    with pytest.raises(EvalError, match="'odd' and 'k' have different seeds"):
        q("mean(paired('odd', 'k', 'last(F)'))")
    with pytest.raises(EvalError, match="different seeds"):
        q("fastest_within(1, 'last(F)', 'k', ['k', 'odd'])")
    with pytest.raises(EvalError, match="needs at least two values"):
        q("sd([1])")
    with pytest.raises(EvalError, match="a list of ensemble names"):
        q("mean(means('k', 'last(F)'))")
    with pytest.raises(EvalError, match="the slowest rate, 2 /s, is beyond 0.1"):
        q("fastest_within(0.1, 'last(F)', 'k', ['j', 'i'])")


def quantity_array(store, expr):
    from harness.compare import evaluate_array
    return evaluate_array(expr, store.get("spring", "soft"), store.siblings("spring"))
