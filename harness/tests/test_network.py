"""Force-network rectangles (C&S Fig. 5(b)): length, width and orientation."""
import math

import pytest

from harness.report import network
from harness.catalogue import load
from harness.errors import IniError


def _discs():
    return [{"name": "a", "x": "0", "y": "0", "r": "2.5"}, {"name": "b", "x": "4.5", "y": "0", "r": "2.0"},
            {"name": "c", "x": "0", "y": "4", "r": "1.5"}]


def _contact(a, b, x, y, nx, ny, fn, fs=0.0):
    return {"a": a, "b": b, "x": str(x), "y": str(y), "nx": str(nx), "ny": str(ny), "fn": str(fn),
            "fs": str(fs), "dn": "0", "ds": "0"}


def _size(corners):
    (x0, y0), (x1, y1), (x2, y2) = corners[0], corners[1], corners[2]
    return math.hypot(x1 - x0, y1 - y0), math.hypot(x2 - x1, y2 - y1)


def test_rectangle_length_is_sum_of_radii_and_width_scales_with_force():
    contacts = [_contact("a", "b", 2.25, 0, 1, 0, 3.0), _contact("a", "c", 0, 2.25, 0, 1, 1.5)]
    boxes, fmax = network.rectangles(_discs(), contacts)
    assert fmax == 3.0
    length0, width0 = _size(boxes[0])
    length1, width1 = _size(boxes[1])
    assert length0 == pytest.approx(4.5)            # R_a + R_b
    assert length1 == pytest.approx(4.0)            # R_a + R_c
    assert width0 == pytest.approx(network.WIDEST_SHARE * 2.5)   # largest force: widest
    assert width1 == pytest.approx(width0 / 2)      # half the force, half the width


def test_rectangle_turns_with_the_shear_force():
    # F_n = 3 along +x, F_s = 4: force on b is 3 e + 4 t with t = (ny, -nx) = (0, -1).
    boxes, fmax = network.rectangles(_discs(), [_contact("a", "b", 2.25, 0, 1, 0, 3.0, 4.0)])
    assert fmax == pytest.approx(5.0)
    (x0, y0), (x1, y1) = boxes[0][0], boxes[0][1]
    assert math.atan2(y1 - y0, x1 - x0) == pytest.approx(math.atan2(-4.0, 3.0))


def test_wall_contact_has_the_disc_radius_as_length():
    boxes, _ = network.rectangles(_discs(), [_contact("a", "floor", 0, -2.5, 0, -1, 1.0)])
    assert _size(boxes[0])[0] == pytest.approx(2.5)


def test_zero_forces_draw_nothing():
    boxes, fmax = network.rectangles(_discs(), [_contact("a", "b", 2.25, 0, 1, 0, 0.0)])
    assert boxes == [] and fmax == 0


def _case_file(tmp_path, figure):
    folder = tmp_path / "fam"
    folder.mkdir()
    (folder / "case.txt").write_text(
        "[case c]\ntier = quick\ntitle = t\nchecks = k\nruntime = 1\n"
        "[variant v]\nscene = s.scene\n[variant w]\nscene = s.scene\n" + figure)
    return tmp_path


def test_network_figure_needs_exactly_one_variant(tmp_path):
    root = _case_file(tmp_path, "[figure f]\nkind = network\nvariants = v w\n")
    with pytest.raises(IniError, match="exactly one variant"):
        load(root)


def test_unknown_figure_kind_is_refused(tmp_path):
    root = _case_file(tmp_path, "[figure f]\nkind = pie\nx = cycle\ny = F\n")
    with pytest.raises(IniError, match="figure kind"):
        load(root)


def test_paper_quote_is_kept(tmp_path):
    root = _case_file(tmp_path, "[figure f]\nkind = network\nvariants = v\npaper = \"a\"\npaper = (p. 5)\n")
    figure = load(root)[0].figures[0]
    assert figure.kind == "network" and figure.paper == "\"a\" (p. 5)"
