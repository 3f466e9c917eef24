"""The VTK snapshots of a biaxial run, read back with a real VTK reader (issue 32, item 2;
docs/paraview.md): Debian's python3-vtk9, which `make test` installs (.ci/install-vtk-deps).
This test skips, saying why, only where `import vtk` fails.

The catalogue's biaxial scene (cases/biaxial/biaxial.scene: 1008 imported discs, four walls
on servos, then a strain-rate shear), shortened with --set, without rolling resistance and
with JYH's Model 1 at delta = 1.6 (the rolling moment array) and Model 2 at delta = 0.4 (lost
rolling springs: rolling state 2), with snapshots every 700 cycles and --vtk.  Every frame's .vtp files are read with vtkXMLPolyDataReader (no error or
warning allowed) and held to the frame's TSV files, exactly (both print %.17g): the discs'
count, centres, radii, ids, velocities, spins, rotations, forces, torques and held flags;
the contacts' count, their lines' ends (the discs' centres, or the contact point on a wall),
fn, fs, mr, sliding, rolling and kind; the walls' ends and forces.  snapshots.pvd, read with
VTK's XML parser, lists each frame's three parts at index.tsv's times, and the last frame is
the run's final discs.tsv and contacts.tsv at series.tsv's last time.
"""
import csv
import subprocess
from pathlib import Path

import numpy as np
import pytest

try:
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
except ImportError as exc:  # the only reason to skip: no VTK for this Python
    pytest.skip(f"VTK's Python module cannot be imported ({exc}): install python3-vtk9 "
                "(sh .ci/install-vtk-deps, which make test runs)", allow_module_level=True)

REPO = Path(__file__).resolve().parents[2]
BALLAST = REPO / "bin" / "ballast"
BIAXIAL = REPO / "cases" / "biaxial" / "biaxial.scene"
EVERY = 700
# 1200 + 1300 cycles: frames at 0, 700, 1400, 2100 and the final state at 2500
SHORT = ["--set", "stage.consolidate.cycles=1200", "--set", "stage.shear.cycles=1300",
         "--set", f"settings.snapshot_every={EVERY}", "--vtk"]
ROLLING = {"no rolling": [], "Model 1 delta 1.6": ["--set", "material.grain.rolling=1.6"],
           "Model 2 delta 0.4": ["--set", "material.grain.rolling=0.4",
                                 "--set", "settings.rolling_model=model2"]}

needs_ballast = pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f, delimiter="\t"))


def column(table, name):
    return np.array([float(r[name]) for r in table])


def read_vtp(path):
    """The PolyData of path, read by VTK's XML reader; fails on any error or warning it raises."""
    problems = []
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    for event in ("ErrorEvent", "WarningEvent"):
        reader.AddObserver(event, lambda obj, ev: problems.append(ev))
    reader.Update()
    assert problems == [], f"{path.name}: VTK reported {problems}"
    return reader.GetOutput()


def array(data, name):
    got = data.GetArray(name)
    assert got is not None, f"no array {name}"
    return vtk_to_numpy(got)


def xyz(table, x="x", y="y"):
    return np.column_stack([column(table, x), column(table, y), np.zeros(len(table))])


def check_discs(poly, table):
    assert poly.GetNumberOfPoints() == len(table) == poly.GetNumberOfVerts()
    pd = poly.GetPointData()
    assert np.array_equal(vtk_to_numpy(poly.GetPoints().GetData()), xyz(table))
    assert np.array_equal(array(pd, "radius"), column(table, "r"))
    assert np.array_equal(array(pd, "id"), column(table, "id"))
    assert np.array_equal(array(pd, "velocity"), xyz(table, "vx", "vy"))
    assert np.array_equal(array(pd, "omega"), column(table, "omega"))
    assert np.array_equal(array(pd, "theta"), column(table, "theta"))
    assert np.array_equal(array(pd, "force"), xyz(table, "fx", "fy"))
    assert np.array_equal(array(pd, "torque"), column(table, "torque"))
    assert np.array_equal(array(pd, "fixed"), column(table, "fixed"))


def check_contacts(poly, table, discs, rolling):
    n = len(table)
    assert poly.GetNumberOfCells() == poly.GetNumberOfLines() == n
    assert poly.GetNumberOfPoints() == 2 * n
    cd = poly.GetCellData()
    assert np.array_equal(array(cd, "fn"), column(table, "fn"))
    assert np.array_equal(array(cd, "fs"), column(table, "fs"))
    assert np.array_equal(array(cd, "sliding"), column(table, "sliding"))
    assert np.array_equal(array(cd, "kind"), np.array([r["kind"] == "wall" for r in table]))
    if rolling:
        assert np.array_equal(array(cd, "mr"), column(table, "mr"))
        assert np.array_equal(array(cd, "rolling"), column(table, "rolling"))
    else:
        assert cd.GetArray("mr") is None
        assert not array(cd, "rolling").any()
    # the lines: from the first disc's centre to the second's, or to the contact point on a wall
    centre = {r["name"]: (float(r["x"]), float(r["y"]), 0.0) for r in discs}
    ends = []
    for r in table:
        ends.append(centre[r["a"]])
        ends.append(centre[r["b"]] if r["kind"] == "disc" else (float(r["x"]), float(r["y"]), 0.0))
    points = vtk_to_numpy(poly.GetPoints().GetData()).reshape(-1, 3)
    assert np.array_equal(points, np.array(ends).reshape(-1, 3))
    lines = vtk_to_numpy(poly.GetLines().GetConnectivityArray())
    assert np.array_equal(lines, np.arange(2 * n))


def check_walls(poly, table):
    assert poly.GetNumberOfCells() == poly.GetNumberOfLines() == len(table)
    points = vtk_to_numpy(poly.GetPoints().GetData())
    assert np.array_equal(points[0::2], xyz(table, "ax", "ay"))
    assert np.array_equal(points[1::2], xyz(table, "bx", "by"))
    assert np.array_equal(array(poly.GetCellData(), "f"), xyz(table, "f1", "f2"))


def read_pvd(path):
    """[(timestep, part, file)] of the collection, read with VTK's XML parser."""
    parser = vtk.vtkXMLDataParser()
    parser.SetFileName(str(path))
    assert parser.Parse() == 1, f"{path}: VTK's XML parser refused it"
    root = parser.GetRootElement()
    assert (root.GetName(), root.GetAttribute("type")) == ("VTKFile", "Collection")
    collection = root.GetNestedElement(0)
    assert collection.GetName() == "Collection"
    out = []
    for k in range(collection.GetNumberOfNestedElements()):
        ds = collection.GetNestedElement(k)
        assert ds.GetName() == "DataSet"
        out.append((ds.GetAttribute("timestep"), int(ds.GetAttribute("part")), ds.GetAttribute("file")))
    return out


@pytest.fixture(scope="module", params=list(ROLLING))
def biaxial_run(request, tmp_path_factory):
    if not BALLAST.exists():
        pytest.skip("bin/ballast not built")
    out = tmp_path_factory.mktemp("vtk") / "run"
    done = subprocess.run([str(BALLAST), "run", str(BIAXIAL), "--out", str(out), *SHORT,
                           *ROLLING[request.param]], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return out, request.param


def test_every_frame_reads_back_as_its_tsv_files(biaxial_run):
    out, model = biaxial_run
    rolling = model != "no rolling"
    snap = out / "snapshots"
    index = rows(snap / "index.tsv")
    assert [int(r["cycle"]) for r in index] == [0, 700, 1400, 2100, 2500]
    walls_seen = lost = 0
    for r in index:
        k = int(r["frame"])
        discs = rows(snap / f"discs.{k:06d}.tsv")
        contacts = rows(snap / f"contacts.{k:06d}.tsv")
        check_discs(read_vtp(snap / f"discs.{k:06d}.vtp"), discs)
        check_contacts(read_vtp(snap / f"contacts.{k:06d}.vtp"), contacts, discs, rolling)
        check_walls(read_vtp(snap / f"walls.{k:06d}.vtp"), rows(snap / f"walls.{k:06d}.tsv"))
        walls_seen += sum(c["kind"] == "wall" for c in contacts)
        lost += sum(c.get("rolling") == "2" for c in contacts)
        assert len(discs) == 1008
        assert k == 0 or len(contacts) > 1000  # a packing under load
    assert walls_seen > 0
    assert (lost > 0) == model.startswith("Model 2")  # the rolling state 2 read back too
    assert len(list(snap.glob("*.vtp"))) == 3 * len(index)


def test_the_collection_lists_every_frame_at_its_time(biaxial_run):
    out, _ = biaxial_run
    snap = out / "snapshots"
    index = rows(snap / "index.tsv")
    listed = read_pvd(snap / "snapshots.pvd")
    want = [(r["time"], part, f"{name}.{int(r['frame']):06d}.vtp")
            for r in index for part, name in enumerate(("discs", "contacts", "walls"))]
    assert listed == want
    times = [float(t) for t, part, _ in listed if part == 0]
    assert times[0] == 0 and all(b > a for a, b in zip(times, times[1:]))
    assert times[-1] == float(rows(out / "series.tsv")[-1]["time"])


def test_the_last_frame_is_the_final_state(biaxial_run):
    out, _ = biaxial_run
    snap = out / "snapshots"
    last = int(rows(snap / "index.tsv")[-1]["frame"])
    final_discs, final_contacts = rows(out / "discs.tsv"), rows(out / "contacts.tsv")
    discs = read_vtp(snap / f"discs.{last:06d}.vtp")
    assert discs.GetNumberOfPoints() == len(final_discs)
    assert np.array_equal(vtk_to_numpy(discs.GetPoints().GetData()), xyz(final_discs))
    assert np.array_equal(array(discs.GetPointData(), "radius"), column(final_discs, "r"))
    contacts = read_vtp(snap / f"contacts.{last:06d}.vtp")
    assert contacts.GetNumberOfCells() == len(final_contacts)
    assert np.array_equal(array(contacts.GetCellData(), "fn"), column(final_contacts, "fn"))


@needs_ballast
def test_vtk_without_snapshots_is_refused(tmp_path):
    done = subprocess.run([str(BALLAST), "run", str(BIAXIAL), "--out", str(tmp_path / "o"), "--vtk"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert done.stderr.startswith(f"{BIAXIAL}: --vtk needs snapshots: give settings.snapshot_every")
    assert not (tmp_path / "o").exists()
