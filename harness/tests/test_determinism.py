"""Same scene + seed = bitwise-identical outputs, whatever -j and whatever order (issue 7, item 5).

Every variant of every case of the default tier (standard, as `make validate`) is run twice
with the real bin/ballast, into two roots: once with -j 1 in catalogue order, once with -j 2
in a shuffled order (fixed seed), both passes at the same time, so runs of one pass share the
machine with runs of the other.  Every output file must be equal byte for byte: series.tsv,
discs.tsv, contacts.tsv, walls.tsv, stress*.tsv, the snapshots (snapshots/, where a variant writes them),
ballast.stdout (the summary's wall time masked)/stderr, and run.json with
its wall-clock fields (wall_seconds, timers, particle_steps_per_s) masked (the exact solver
writes its solve time there too, not in series.tsv).  Of an [ensemble] only the first
REALISATIONS realisations are run: the others are the same scene with another seed (the
polydisperse piles have a thousand of them, minutes of CPU that would say nothing new).  About
30 s of CPU (two passes of ~15 s); skipped when bin/ballast is not built (`make test` builds it).
"""
import io
import random
import threading
from pathlib import Path

import pytest

from harness import catalogue
from harness.runner import jobs_for, run_all
from harness.tests.test_interrupt import BALLAST, REPO, without_summary_clock, without_wall_clock

DEFAULT_TIER = "standard"
SEED = 1979
REALISATIONS = 3


def kept(cases):
    """(case, variant) of every plain variant and of the first REALISATIONS of each ensemble."""
    return {(c.name, v.name) for c in cases for v in c.variants
            if not v.ensemble or v.name in c.ensemble(v.ensemble).members[:REALISATIONS]}


def jobs_kept(cases, root):
    chosen = kept(cases)
    return [j for j in jobs_for(cases, root) if (j.case, j.variant) in chosen]


def outputs(job):
    """{file: bytes} of a job's folder, its sub-folders too (snapshots/); run.json without its
    wall-clock fields; not harness.json (the runner's record: paths and wall time)."""
    out = {}
    for path in sorted(p for p in Path(job.out).rglob("*") if p.is_file()):
        if path.name == "harness.json":
            continue
        data = path.read_bytes()
        if path.name == "run.json":
            data = without_wall_clock(data)
        elif path.name == "ballast.stdout":
            data = without_summary_clock(data)
        out[str(path.relative_to(job.out))] = data
    return out


@pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")
def test_default_tier_is_bitwise_identical_whatever_jobs_and_order(tmp_path):
    cases = catalogue.select(catalogue.load(REPO / "cases"), [], DEFAULT_TIER)
    in_order = jobs_kept(cases, tmp_path / "j1")
    shuffled = jobs_kept(cases, tmp_path / "j2")
    random.Random(SEED).shuffle(shuffled)
    assert [j.label for j in shuffled] != [j.label for j in in_order]

    result = {}
    first = threading.Thread(target=lambda: result.update(j1=run_all(in_order, BALLAST, 1, io.StringIO())))
    first.start()
    result["j2"] = run_all(shuffled, BALLAST, 2, io.StringIO())
    first.join()
    for name in ("j1", "j2"):
        failed = [f"{o.job.label}: {o.cause}" for o in result[name] if not o.ok]
        assert not failed, failed

    differ = []
    by_label = {j.label: j for j in shuffled}
    for a in in_order:
        left, right = outputs(a), outputs(by_label[a.label])
        assert set(left) == set(right), a.label
        assert {"series.tsv", "run.json"} <= set(left), a.label
        differ += [f"{a.label}/{name}" for name in left if left[name] != right[name]]
    assert not differ, f"outputs differ between -j 1 in order and -j 2 shuffled: {differ}"
    assert len(in_order) == len(kept(cases)) >= 40
