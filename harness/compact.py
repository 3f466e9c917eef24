"""What a validate keeps under reports/ once its report is written (issue 32, item 4).

A default validate wrote 322 MB: 136 MB the tables of the 1 000 realisations of piles_poly's
ensembles, 92 MB the tables of the 99 error-against-cost sweep points, 40 MB the series.tsv of
the cases' own runs, 33 MB the figures; it kept 52 MB (65 MB once the biaxial snapshots and the
shear-band figures came, 2026-11-28).  Once the report is written nothing reads most of it again: the verdicts are
in summary.json and junit.xml, the figures in figures/, each sweep's results in its cost.tsv.  So
validate, at its very end (an interrupted validate keeps every file, and --resume works as
before), keeps:

  * a case's own runs (its [variant]s) whole, but a series.tsv of GZIP_MIN bytes or more as
    series.tsv.gz, which every reader of the harness reads as it read series.tsv
    (tables.read_text) -- `check`, `report`, `rebaseline` and --resume go on from it unchanged;
  * of a realisation of an [ensemble] and of a declared sweep point only what says what ran and
    how it ended (KEPT: run.json, the runner's harness.json, the core's stderr; a realisation
    its small series.tsv too), the tables removed: their statistics and errors are in the
    report, summary.json and cost.tsv;
  * a run that failed whole, whatever it is: a reader needs its outputs to see why.

What was done is recorded in the run's harness.json under "compacted" (its time of writing kept,
so the report still finds summary.json fresh), and --resume reads it: a gzipped series.tsv is
the run's own file, a run whose tables were removed is run again, and a check or figure that
needs those tables says they were removed and how to get them back (`harness run CASE`, or a
validate with --keep-outputs, which keeps every file as the runs wrote it).
"""
import gzip
import hashlib
import json
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from . import files, sweep
from .tables import read_harness_record

KEPT = ("run.json", "harness.json", "ballast.stderr")   # ballast.stdout: its one line is in run.json
# A realisation keeps its series.tsv too (a few KiB): every check of a run loads it
# (tables.load_run), so its checks on run.json alone -- the energy audit of each realisation --
# still evaluate after validate; the checks over the ensemble need the removed tables.
REALISATION_KEPT = KEPT + ("series.tsv",)
GZIPPED = ("series.tsv",)      # of a case's own runs: the one table every check reads, and the largest
# A table below this stays plain: it takes whole 4 KiB blocks on disk either way, so gzip would
# gain at most some 40 KiB a file (the quick cases' two-disc series, the fake project's runs),
# and a plain file is one a reader opens without zcat.
GZIP_MIN = 64 * 1024
# gzip's fastest level: on the 37 series of the default tier (39.8 MB) it writes 16.4 MB in 0.32 s
# of CPU, level 6 (the default) 15.2 MB in 1.64 s -- 8 % more bytes for a fifth of the time, which
# the pre-commit gate (`make gate`, about 6 s) pays too.
GZIP_LEVEL = 1


@dataclass
class Tally:
    gzipped: int = 0           # series.tsv files written as .gz
    gzip_saved: int = 0        # bytes saved by them
    realisations: int = 0      # realisations whose tables were removed
    points: int = 0            # sweep points whose tables were removed
    drop_saved: int = 0        # bytes removed

    def text(self):
        return (f"{self.gzipped} series.tsv gzipped ({self.gzip_saved / 1e6:.0f} MB saved), the tables of "
                f"{self.realisations} ensemble realisation(s) and {self.points} sweep point(s) removed "
                f"({self.drop_saved / 1e6:.0f} MB)")


def _record(folder):
    """harness.json of a run that succeeded and is not compacted yet, else None."""
    record = read_harness_record(folder)
    if not record or not record.get("ok") or not isinstance(record.get("outputs"), dict):
        return None
    return record


def _write_record(folder, record):
    """harness.json rewritten whole with its modification time kept: the run was made when it was."""
    path = Path(folder) / "harness.json"
    stat = path.stat()
    files.write_text(path, json.dumps(record, indent=1) + "\n")
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))


def gzip_tables(folder, tally):
    """A case's own run: each GZIPPED table of GZIP_MIN bytes or more as NAME.gz, recorded."""
    folder = Path(folder)
    record = _record(folder)
    if record is None:
        return
    done = dict(record.get("compacted", {}).get("gzip", {}))
    for name in GZIPPED:
        plain = folder / name
        if name in done or not plain.is_file() or plain.stat().st_size < GZIP_MIN:
            continue
        data = plain.read_bytes()
        packed = gzip.compress(data, compresslevel=GZIP_LEVEL, mtime=0)     # mtime 0: the same bytes every time
        files.write_bytes(folder / (name + ".gz"), packed)
        done[name] = sha256_bytes(packed)
        record.setdefault("compacted", {})["gzip"] = done
        _write_record(folder, record)
        files.remove(plain)
        tally.gzipped += 1
        tally.gzip_saved += len(data) - len(packed)


def drop_tables(folder, tally, kept=KEPT):
    """A realisation or a sweep point: every file but those named in kept removed, recorded with
    its digest.  True when it removed some."""
    folder = Path(folder)
    record = _record(folder)
    if record is None or record.get("compacted", {}).get("removed"):
        return False
    gone = sorted(p for p in folder.iterdir() if p.name not in kept)
    if not gone:
        return False
    record.setdefault("compacted", {})["removed"] = {p.name: record["outputs"].get(p.name) for p in gone}
    _write_record(folder, record)
    for p in gone:
        size = _size(p)
        if p.is_dir() and not p.is_symlink():
            try:
                shutil.rmtree(p)
            except OSError as exc:
                raise files.failure("remove", p, exc) from exc
        else:
            files.remove(p)
        tally.drop_saved += size
    return True


def compact(cases, runs_root, sweeps_root=None):
    """The runs and declared sweep points of cases (none when sweeps_root is None: a validate
    without its sweeps leaves what an earlier `cost` wrote), compacted as the module says; a Tally."""
    tally = Tally()
    for case in cases:
        for v in case.variants:
            folder = Path(runs_root) / case.name / v.name
            if not folder.is_dir():
                continue
            if v.ensemble:
                tally.realisations += drop_tables(folder, tally, REALISATION_KEPT)
            else:
                gzip_tables(folder, tally)
        if case.sweeps and sweeps_root is not None:
            for job in sweep.jobs(case, sweeps_root):
                if Path(job.out).is_dir():
                    tally.points += drop_tables(job.out, tally)
    return tally


def sha256_bytes(data):
    return hashlib.sha256(data).hexdigest()


def _size(path):
    if path.is_file() or path.is_symlink():
        return path.lstat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file() and not p.is_symlink())


def disk(path):
    """Bytes of every file under path (links not followed): what a folder holds."""
    total = 0
    for d, _, names in os.walk(path):
        for n in names:
            p = os.path.join(d, n)
            if not os.path.islink(p):
                try:
                    total += os.path.getsize(p)
                except OSError:
                    pass
    return total
