"""harness/engines/questions.py: the agreement matrix's questions (reference/questions.txt), the
tables of named quantities it answers with two engines beside the paper (issue 34, item 4)."""
import json

import pytest

from harness import catalogue, cases_root
from harness.engines import matrix, questions
from harness.errors import EvalError, IniError, RunNotExpressible, RunProblem

CASES = catalogue.load(cases_root())

TEXT = """[table t]
title = a question
question = do they agree?
columns = a b
format = .3f

[row r1]
table = t
label = first
case = two_discs
variant = {variant}
quantity.a = 1
quantity.b = 2
paper.a = 1.5
provenance = a paper, eq. 1
"""


def write(tmp_path, text):
    p = tmp_path / "questions.txt"
    p.write_text(text)
    return p


def test_the_committed_questions_load_and_name_runs_of_the_catalogue():
    tables = {t.name: t for t in questions.check_loaded(CASES)}
    phi = tables["biaxial_phi"]
    assert phi.columns == ["peak", "residual"]
    rows = {(r.case, r.variant) for r in phi.rows}
    # the two open questions of issue 34: e = 0.25 (the full tier's tests) and e = 0.20, JYH's four materials
    for m in ("m0", "m1_d0.4", "m1_d1.6", "m2_d0.4"):
        assert ("biaxial_full", f"{m}_s200") in rows and ("biaxial", f"{m}_s200_e020") in rows
    assert all(r.paper["peak"] and r.provenance.startswith("JYH") for r in phi.rows)
    dip = tables["pile_dip"]
    assert {(r.case, r.ensembles) for r in dip.rows} >= {("piles_poly_full", ("dip",)), ("piles_poly_full", ("hump",))}


def test_a_row_in_a_case_the_matrix_does_not_hold_has_its_runs_made():
    tables = questions.check_loaded(CASES)
    standard = catalogue.select(CASES, (), "standard")
    extra = {c.name: c for c in questions.extra_cases(tables, CASES, standard, 10)}
    assert set(extra) == {"biaxial_full", "piles_poly_full"}          # biaxial and piles_poly are standard
    # the e025 tests at 200 kPa, and at 100 and 400 kPa for the envelopes (a row's `reads`)
    assert {v.name for v in extra["biaxial_full"].variants} == {
        f"{m}_s{p}" for m in ("m0", "m1_d0.4", "m1_d1.6") for p in (100, 200, 400)} | {"m2_d0.4_s200"}
    full = extra["piles_poly_full"]
    assert [e.name for e in full.ensembles] == ["hump", "dip"] or [e.name for e in full.ensembles] == ["dip", "hump"]
    assert all(len(e.members) == 10 for e in full.ensembles)
    assert len(full.variants) == 20 and "mono" not in full.variant_names()
    # every run of the full tier's matrix is already there: nothing extra
    assert questions.extra_cases(tables, CASES, catalogue.select(CASES, (), "full"), 10) == []
    # all the realisations with 0
    whole = questions.extra_cases(tables, CASES, standard, 0)
    assert sum(len(e.members) for c in whole for e in c.ensembles) == 800


def test_named_cases_answer_only_the_tables_with_a_row_in_them():
    tables = questions.check_loaded(CASES)
    assert [t.name for t in questions.chosen(tables, ["biaxial"])] == ["biaxial_phi"]
    assert [t.name for t in questions.chosen(tables, ["biaxial_full"])] == ["biaxial_phi", "biaxial_envelope"]
    assert [t.name for t in questions.chosen(tables, ["collisions"])] == []
    assert len(questions.chosen(tables)) == len(tables)


@pytest.mark.parametrize("change, line, words", [
    (("quantity.b = 2", "quantity.b = 2\nwidth = 3"), 14, "unknown key 'width'"),
    (("quantity.b = 2", "quantity.c = 2"), 13, "'quantity.c': [table t] has no column 'c'"),
    (("quantity.b = 2\n", ""), 7, "needs 'quantity.b = ...'"),
    (("table = t\n", "table = u\n"), 8, "'table = u' names no [table]"),
    (("provenance = a paper, eq. 1\n", ""), 7, "needs 'provenance = ...'"),
    (("format = .3f", "format = %d"), 5, "'format' is not a number format"),
    (("columns = a b", "columns = a a"), 4, "names a column twice"),
    (("label = first\n", "label = first\nlabel = again\n"), 10, "'label' given twice"),
])
def test_a_malformed_question_names_its_file_line_and_key(tmp_path, change, line, words):
    p = write(tmp_path, TEXT.format(variant="v").replace(*change))
    with pytest.raises(IniError) as err:
        questions.load(p)
    assert f"questions.txt:{line}:" in str(err.value) and words in str(err.value)


def test_a_row_naming_a_variant_the_case_lacks_is_an_error_at_the_row(tmp_path):
    p = write(tmp_path, TEXT.format(variant="no_such_variant"))
    tables = questions.load(p)
    with pytest.raises(IniError) as err:
        questions.validate(tables, CASES)
    assert "questions.txt:7:" in str(err.value) and "no variant 'no_such_variant'" in str(err.value)
    two = catalogue.select(CASES, ["two_discs"])[0].variants[0].name
    reads = TEXT.format(variant=two).replace("label = first", "label = first\nreads = not_there")
    with pytest.raises(IniError) as err:
        questions.validate(questions.load(write(tmp_path, reads)), CASES)
    assert "questions.txt:7:" in str(err.value) and "no variant 'not_there'" in str(err.value)
    questions.validate(questions.load(write(tmp_path, TEXT.format(variant=two))), CASES)


class Store:
    """A RunStore stand-in: the engine's name, for the fake quantity_in below."""
    def __init__(self, name):
        self.name = name


def fake_quantity(values):
    def quantity_in(store, case, variant, expr):
        v = values[store.name].get((variant, expr))
        if isinstance(v, Exception):
            raise v
        return v
    return quantity_in


def test_each_cell_is_a_value_or_why_not_and_the_engines_differences_are_taken(tmp_path, monkeypatch):
    text = TEXT.format(variant="v1") + """
[row r2]
table = t
label = second
case = two_discs
variant = v2
quantity.a = 1
quantity.b = 2
"""
    tables = questions.load(write(tmp_path, text))
    values = {"ballast": {("v1", "1"): 1.0, ("v1", "2"): 2.0, ("v2", "1"): 3.0, ("v2", "2"): 4.0},
              "engine": {("v1", "1"): 1.25, ("v1", "2"): RunNotExpressible("model2: no counterpart"),
                         ("v2", "1"): RunProblem("no run.json"), ("v2", "2"): EvalError("'2' raised")}}
    monkeypatch.setattr(questions, "quantity_in", fake_quantity(values))
    [a] = questions.answer(tables, Store("ballast"), Store("engine"))
    r1, r2 = a["rows"]
    assert r1["cells"]["a"]["engine_ballast"] == 0.25
    assert r1["cells"]["a"]["ballast_paper"] == -0.5 and r1["cells"]["a"]["engine_paper"] == -0.25
    assert r1["cells"]["b"]["engine"]["why"] == "NOT EXPRESSIBLE" and r1["cells"]["b"]["engine_ballast"] is None
    assert r2["cells"]["a"]["engine"]["why"] == "not run" and r2["cells"]["b"]["engine"]["why"] == "error"
    assert a["largest"]["a"] == {"engine_ballast": 0.25, "ballast_paper": -0.5, "engine_paper": -0.25}
    md = "\n".join(questions.markdown([a], "LAMMPS"))
    assert "| first | 1.5 | 1.000 | 1.250 | +0.250 | 2.000 | NOT EXPRESSIBLE | - |" in md
    assert "second in LAMMPS: NOT EXPRESSIBLE" not in md and "first in LAMMPS: NOT EXPRESSIBLE: model2" in md
    assert "LAMMPS − ballast +0.250, ballast − paper -0.500, LAMMPS − paper -0.250" in md
    page = "\n".join(questions.html_part([a], "LAMMPS"))
    assert "NOT EXPRESSIBLE" in page and "+0.250" in page


def test_the_matrix_writes_its_questions_and_a_matrix_of_some_cases_keeps_the_others(tmp_path, monkeypatch):
    out = tmp_path / "peers"
    q = lambda name, v: {"table": name, "title": name, "question": "?", "columns": ["a"], "format": ".3g",
                         "notes": [], "largest": {"a": {"engine_ballast": None, "ballast_paper": None,
                                                        "engine_paper": None}},
                         "rows": [{"row": "r", "label": "L", "case": "c", "variant": "v", "provenance": "",
                                   "cells": {"a": {"paper": "", "ballast": {"value": v},
                                                   "engine": {"value": v}, "engine_ballast": 0.0,
                                                   "ballast_paper": None, "engine_paper": None}}}]}
    matrix.write([], "lammps", "LAMMPS", 10, out, [q("one", 1.0), q("two", 2.0)])
    md = (out / "index.md").read_text()
    assert "## Question: one" in md and "## Question: two" in md and "| L | 1 | 1 | +0 |" in md
    old = matrix.previous("lammps", out)["questions"]
    kept = questions.merged([q("one", 3.0)], old, ["one", "two"])
    assert [a["table"] for a in kept] == ["one", "two"] and kept[0]["rows"][0]["cells"]["a"]["ballast"]["value"] == 3.0
    assert matrix.previous("other", out) == {}
    assert json.loads((out / "matrix.json").read_text())["questions"][0]["table"] == "one"
