"""rebaseline: the only code that writes reference files.

For every `kind = regression` check of one case, recompute the quantity from the current
run outputs and rewrite the number on its `value = ` line in place, keeping every other
character of the file (comments, spacing, other checks).  Nothing is written unless every
run of the case succeeded and every regression quantity evaluates to a finite number.
"""
import re
from pathlib import Path

from . import files
from .compare import quantity_in
from .errors import EvalError, RunProblem

VALUE_LINE = re.compile(r"^(\s*value\s*=\s*)([^#]*?)(\s*(?:#.*)?)$")


def recompute(check, store):
    """The new reference value of an abs/rel/ratio check from current outputs."""
    q = quantity_in(store, check.case, check.variant, check.quantity)
    if check.tolerance != "ratio":
        return q
    other = quantity_in(store, check.case, check.other_variant, check.other)
    if other == 0:
        raise EvalError(f"{check.other_variant}: other quantity '{check.other}' is zero")
    return q / other


def run_problems(case, store):
    """Why some run of the case cannot be used (empty when all are fine)."""
    problems = []
    for variant in case.variant_names():
        try:
            store.get(case.name, variant)
        except RunProblem as problem:
            problems.append(f"{case.name}/{variant}: {problem}")
    return problems


def new_values(checks, store):
    """[(check, new value)] for the checks that carry a value, and a list of problems."""
    values, problems = [], []
    for check in checks:
        if check.tolerance in ("interval", "trend"):
            continue
        try:
            values.append((check, recompute(check, store)))
        except (RunProblem, EvalError) as exc:
            problems.append(f"{check.name}: {exc}")
    return values, problems


def replace_value(line, new_text):
    """line with the number after 'value =' replaced; the comment and line ending are kept."""
    body = line.rstrip("\r\n")
    ending = line[len(body):]
    match = VALUE_LINE.match(body)
    if not match:
        raise ValueError(f"not a 'value = ...' line: {body!r}")
    return match.group(1) + new_text + match.group(3) + ending


def rewrite_file(path, changes):
    """Apply {line number: new value text} to path, writing through a temporary file."""
    path = Path(path)
    with open(path, encoding="utf-8", newline="") as f:      # newline="": keep the file's line endings
        lines = f.read().splitlines(keepends=True)
    for number, text in changes.items():
        lines[number - 1] = replace_value(lines[number - 1], text)
    files.write_text(path, "".join(lines))     # bytes as read: line endings kept


def rebaseline(case, checks, store, out):
    """Rewrite the regression values of case; the exit status (non-zero = refused)."""
    mine = [c for c in checks if c.case == case.name and c.kind == "regression"]
    if not mine:
        print(f"rebaseline {case.name}: no regression checks, nothing to do", file=out)
        return 0
    problems = run_problems(case, store)
    values, eval_problems = new_values(mine, store) if not problems else ([], [])
    problems += eval_problems
    if problems:
        print(f"rebaseline {case.name}: refused, nothing written:", file=out)
        print("\n".join(f"  {p}" for p in problems), file=out)
        return 1
    for check in mine:
        if check.tolerance in ("interval", "trend"):
            print(f"{check.name}: {check.tolerance} check has no value to rebaseline", file=out)
    changed = apply_changes(values, out)
    print(f"{changed} value(s) changed, {len(values) - changed} unchanged", file=out)
    return 0


def apply_changes(values, out):
    """Rewrite every value that changed, printing 'check: old -> new'; how many changed."""
    by_file = {}
    for check, new in values:
        if new != check.value:
            by_file.setdefault(check.path, {})[check.value_line] = repr(new)
            print(f"{check.name}: {check.value!r} -> {new!r}", file=out)
    for path, changes in by_file.items():
        rewrite_file(path, changes)
    return sum(len(c) for c in by_file.values())
