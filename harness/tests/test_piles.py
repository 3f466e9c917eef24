"""The pile and network functions of the quantity expressions (families/piles.py,
families/networks.py) on the hand-made pile of pile_fakes.py: stress profiles in MLH units (compression positive), horizontal contacts,
contact forces against another variant, and every missing input an EvalError (a FAIL)."""
import math

import numpy as np
import pytest

from harness.compare import RunStore, evaluate, evaluate_check, folder_locator, namespace
from harness.errors import EvalError
from harness.families import piles
from harness.references import load_file
from harness.tables import load_run
from harness.tests import pile_fakes
from harness.tests.pile_fakes import write_pile_run

R2 = math.sqrt(2)


@pytest.fixture
def root(tmp_path):
    root = tmp_path / "runs"
    write_pile_run(root / "pile" / "dem")
    write_pile_run(root / "pile" / "exact", exact=True)
    return root


@pytest.fixture
def store(root):
    return RunStore(folder_locator(root))


def value(store, expr, variant="dem"):
    return evaluate(expr, store.get("pile", variant), lambda other: store.get("pile", other))


def array(store, expr, variant="dem"):
    """An array-valued expression, through the namespace the checks use."""
    run = store.get("pile", variant)
    names = namespace(run, lambda other: store.get("pile", other))
    return eval(expr, {**names, "__builtins__": {}})  # noqa: S307 -- test only


# ---------------------------------------------------------------- profiles

def test_pile_X_sorts_the_row_by_x(store):
    assert array(store, "pile_X()") == pytest.approx([0.25, 0.5, 0.75])
    assert array(store, "pile_X(1)") == pytest.approx([0.25, 0.5, 0.75])
    assert array(store, "pile_X(row=0)") == pytest.approx([0.125, 0.375, 0.625, 0.875])
    assert array(store, "pile_X(2)") == pytest.approx([0.375, 0.625])


@pytest.mark.parametrize("component, expected", [
    ("xx", [1.0, 0.5, -0.5]),
    ("zz", [2.0, 1.5, 1.0]),
    ("xz", [0.0, 0.5, 0.0]),
    ("max", [2.0, (4 + 2 * R2) / 4, 1.0]),
    ("min", [1.0, (4 - 2 * R2) / 4, -0.5]),
    ("phi", [90.0, 67.5, 90.0]),
    ("ratio", [0.5, (4 - 2 * R2) / (4 + 2 * R2), -0.5]),
])
def test_pile_S_is_scaled_compression_positive_and_aligned_with_pile_X(store, component, expected):
    assert array(store, f"pile_S('{component}')") == pytest.approx(expected)
    assert array(store, f"pile_S('{component}', 1)") == pytest.approx(expected)


def test_phi_is_the_most_compressive_axis():
    """For p.6 the eigenvector of the most compressive value (-6.83) is at 67.5 degrees."""
    tensor = np.array([[-2.0, -2.0], [-2.0, -6.0]])
    values, vectors = np.linalg.eigh(tensor)
    v = vectors[:, np.argmin(values)]
    assert math.degrees(math.atan2(v[1], v[0])) % 180 == pytest.approx(67.5)


def test_middle():
    assert piles.middle([3.0, 1.0, 2.0]) == 1.0            # the middle element, not the median
    assert piles.middle([1.0, 2.0, 4.0, 8.0]) == 3.0
    assert piles.middle(np.array([7.0])) == 7.0
    with pytest.raises(EvalError, match="empty"):
        piles.middle([])


def test_middle_of_a_profile_as_a_check_quantity(store):
    assert value(store, "middle(pile_S('zz'))") == pytest.approx(1.5)
    assert value(store, "middle(pile_X(0))") == pytest.approx(0.5)
    assert value(store, "max(pile_S('max'))") == pytest.approx(2.0)


def test_weight_uses_gravity_of_run_json(tmp_path, store):
    assert value(store, "weight()") == pytest.approx(16.0)            # 8 free mass * |g| = 2
    write_pile_run(tmp_path / "p" / "g1", gravity=None)
    run = load_run(tmp_path / "p" / "g1")
    assert evaluate("weight()", run) == pytest.approx(8.0)           # |g| = 1 when absent
    assert evaluate("middle(pile_S('zz'))", run) == pytest.approx(3.0)  # l / W = 4 / 8


def test_a_probe_column_named_like_a_function_is_still_the_column(tmp_path):
    folder = write_pile_run(tmp_path / "p" / "v", series={"cycle": [0, 1], "time": [0, 1], "weight": [5, 16]})
    run = load_run(folder)
    assert evaluate("weight() / last(weight)", run) == pytest.approx(1.0)


# ---------------------------------------------------------------- contacts

def test_horizontal_contacts(store):
    assert value(store, "horizontal_contacts()") == 3          # 0 and 5 degrees in row 1, 0 in row 2
    assert value(store, "horizontal_contacts(0, 0.5)") == 2     # X = .375 and .5
    assert value(store, "horizontal_contacts(xlo=0.6, xhi=1)") == 1
    assert value(store, "horizontal_contacts(row_min=2)") == 1
    assert value(store, "horizontal_contacts(0, 0.3)") == 0
    assert value(store, "horizontal_contacts()", "exact") == 2  # the open p.7-p.8 is not touching


def test_horizontal_contacts_angle_limit(tmp_path):
    """Normals at 0, 5, 15 and 60 degrees (and their mirror images): the first two count."""
    folder = write_pile_run(tmp_path / "p" / "v")
    lines = ["a\tb\tkind\tx\ty\tnx\tny\tfn\tfs\tdn\tds\tsliding"]
    for angle in (0, 5, 15, 60, 180, 175, 165, -5, 9.9, 10.1):
        lines.append(f"p.5\tp.6\tdisc\t1.5\t1.4\t{math.cos(math.radians(angle))!r}\t"
                     f"{math.sin(math.radians(angle))!r}\t1\t0\t0\t0\t0")
    (folder / "contacts.tsv").write_text("\n".join(lines) + "\n")
    assert evaluate("horizontal_contacts()", load_run(folder)) == 6      # 0 5 180 175 -5 9.9


def test_contact_error_and_mismatch(store):
    assert value(store, "contact_error('exact')") == pytest.approx(3 / 24)
    assert value(store, "contact_error('exact', 'all')") == pytest.approx(3 / 24)
    assert value(store, "contact_error('exact', kind='disc')") == pytest.approx(3 / 10)
    assert value(store, "contact_error('exact', kind='wall')") == pytest.approx(1 / 24)
    assert value(store, "contact_error('dem')", "exact") == pytest.approx(3 / 23)   # held pair left out
    assert value(store, "contact_error('dem')") == 0.0
    assert value(store, "contact_mismatch('exact')") == 2
    assert value(store, "contact_mismatch('dem')", "exact") == 2
    assert value(store, "contact_mismatch('dem')") == 0


def test_contact_error_bad_kind(store):
    with pytest.raises(EvalError, match="kind must be one of all, wall, disc"):
        value(store, "contact_error('exact', 'floor')")


# ---------------------------------------------------------------- failures are FAILs

def _check(tmp_path, quantity, variant="dem"):
    path = tmp_path / "c.ref"
    path.write_text(f"[check c]\ncase = pile\nvariant = {variant}\nquantity = {quantity}\nvalue = 1\n"
                    "tolerance = abs 1e300\nkind = analytic\nprovenance = test\n")
    return load_file(path)[0]


@pytest.mark.parametrize("remove, quantity, words", [
    ("stress.tsv", "middle(pile_S('zz'))", "stress.tsv missing"),
    ("discs.tsv", "middle(pile_X())", "discs.tsv missing"),
    ("discs.tsv", "weight()", "discs.tsv missing"),
    ("contacts.tsv", "horizontal_contacts()", "contacts.tsv missing"),
    ("contacts.tsv", "contact_error('exact')", "contacts.tsv missing"),
])
def test_missing_files_fail(tmp_path, root, store, remove, quantity, words):
    (root / "pile" / "dem" / remove).unlink()
    verdict = evaluate_check(_check(tmp_path, quantity), store)
    assert not verdict.passed and words in verdict.message and verdict.value is None


@pytest.mark.parametrize("quantity, words", [
    ("contact_error('exact')", "contact_error('exact'): contacts.tsv missing"),
    ("contact_mismatch('exact')", "contact_mismatch('exact'): contacts.tsv missing"),
])
def test_missing_files_of_the_other_variant_fail(tmp_path, root, store, quantity, words):
    (root / "pile" / "exact" / "contacts.tsv").unlink()
    verdict = evaluate_check(_check(tmp_path, quantity), store)
    assert not verdict.passed and words in verdict.message


@pytest.mark.parametrize("quantity, words", [
    ("contact_error('nope')", "variant 'nope': run output missing"),
    ("middle(pile_S('yy'))", "component must be one of"),
    ("middle(pile_X(5))", "no disc in pile row 5"),
    ("middle(pile_X(1.5))", "row must be a whole number"),
    ("middle(pile_S('zz', 7))", "no disc in pile row 7"),
    ("middle(pile_S('zz'))", None),                              # the fixture itself passes
])
def test_bad_arguments_fail(tmp_path, store, quantity, words):
    verdict = evaluate_check(_check(tmp_path, quantity), store)
    if words is None:
        assert verdict.passed
    else:
        assert not verdict.passed and words in verdict.message, verdict.message


def test_no_pile_in_run_json_fails(tmp_path):
    run = load_run(write_pile_run(tmp_path / "p" / "v", pile=False))
    for expr in ("middle(pile_X())", "middle(pile_S('zz'))", "horizontal_contacts()"):
        with pytest.raises(EvalError, match="run.json has no piles"):
            evaluate(expr, run)
    assert evaluate("weight()", run) == pytest.approx(16.0)     # the weight needs no pile


def test_malformed_tables_name_file_and_line(tmp_path):
    folder = write_pile_run(tmp_path / "p" / "v")
    lines = (folder / "discs.tsv").read_text().splitlines()
    lines[3] = lines[3].replace("\t2.5\t", "\tabc\t", 1)         # line 4: disc p.2
    (folder / "discs.tsv").write_text("\n".join(lines) + "\n")
    with pytest.raises(EvalError, match=r"discs\.tsv:4: x is not a number: 'abc'"):
        evaluate("weight()", load_run(folder))
    (folder / "discs.tsv").write_text("id\tname\tx\n0\tp.0\t1\n")
    with pytest.raises(EvalError, match=r"discs\.tsv:1: column\(s\) missing from discs\.tsv: y, r, m, fixed, row"):
        evaluate("weight()", load_run(folder))
    (folder / "discs.tsv").write_text("")
    with pytest.raises(EvalError, match="empty"):
        evaluate("weight()", load_run(folder))


def test_zero_weight_fails(tmp_path):
    run = load_run(write_pile_run(tmp_path / "p" / "v", gravity=(0.0, 0.0)))
    with pytest.raises(EvalError, match="not positive"):
        evaluate("weight()", run)


def test_contacts_naming_unknown_discs_fail(tmp_path):
    folder = write_pile_run(tmp_path / "p" / "v")
    (folder / "contacts.tsv").write_text("a\tb\tkind\tx\ty\tnx\tny\tfn\tfs\tdn\tds\tsliding\n"
                                         "p.5\tq.9\tdisc\t1\t1\t1\t0\t1\t0\t0\t0\t0\n")
    with pytest.raises(EvalError, match="'q.9'"):
        evaluate("horizontal_contacts()", load_run(folder))


def test_files_are_read_once_per_run(tmp_path):
    run = load_run(write_pile_run(tmp_path / "p" / "v"))
    assert evaluate("weight()", run) == pytest.approx(16.0)
    (run.folder / "discs.tsv").unlink()
    assert evaluate("weight() + middle(pile_X())", run) == pytest.approx(16.5)   # cached


def test_namespace_reads_nothing_until_called(tmp_path):
    """A run without any final-state file still evaluates series quantities."""
    folder = write_pile_run(tmp_path / "p" / "v")
    for name in ("discs.tsv", "contacts.tsv", "stress.tsv", "walls.tsv"):
        (folder / name).unlink()
    assert evaluate("last(Ek)", load_run(folder)) == 0.5


def test_pile_S_of_another_variant(tmp_path):
    """pile_S(component, row, variant) reads a sibling variant's final state."""
    a = pile_fakes.write_pile_run(tmp_path / "a")
    b = pile_fakes.write_pile_run(tmp_path / "b")
    runs = {"b": load_run(b)}
    this = load_run(a)
    same = evaluate("max(abs(pile_S('zz') - pile_S('zz', 1, 'b')))", this, runs.__getitem__)
    assert same == 0.0
