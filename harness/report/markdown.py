"""reports/summary.md and the case pages reports/cases/<case>.md, from what contents.py gathered.

summary.md is short whatever the catalogue's size (issue 32, item 4): the verdict, the failures,
the skipped checks, the KNOWN list, one row per case with its counts and a link to its page, and
the stability digest with a link to reports/stability.md.  Each case's full tables (runs, energy
audit, figures, every check, error against cost) are on its own page, cases/<case>.md."""
from .. import sweep
from ..gate import counts_text, fmt_number, fmt_reference
from .contents import ENERGY_COLUMNS, case_counts, energy_cells, skip_groups, stability_digest, stability_tables
from .cost_plot import UNSTABLE

CASES_DIR = "cases"                 # the case pages, beside summary.md and index.html
STABILITY_PAGE = "stability"        # reports/stability.md and .html: the limits and the extreme probes


def markdown(reports, revision, date, known_lines=(), reports_dir=None):
    """summary.md: the verdict first, then the failures, the skipped checks, known_lines (every
    KNOWN discrepancy of the catalogue: known_list.py), the table of the cases (their counts and
    links to their pages), and the stability digest (when reports_dir holds its tables)."""
    verdicts = [v for r in reports for v in r.verdicts]
    lines = ["# ballast validation report", "", f"Revision `{revision}`, {date}. **{counts_text(verdicts)}.**", ""]
    failures = [v for v in verdicts if v.result == "FAIL"]
    if failures:
        lines += [f"## Failures ({len(failures)})", ""]
        lines += [f"- **FAIL** {v.case}/{v.check} ({v.variant}): {_md(v.message)}" for v in failures] + [""]
    skips = skip_groups(verdicts)
    if skips:
        lines += [f"## Skipped ({sum(len(n) for n in skips.values())})", ""]
        lines += [f"- **SKIP** {case} ({len(names)} check{'s' if len(names) > 1 else ''}): {_md(message)}"
                  for (case, message), names in skips.items()] + [""]
    lines += list(known_lines)
    lines += [f"## Cases ({len(reports)})", "",
              "Each case's runs, energy audit, figures, every check and its error against cost are on its page.", "",
              "| case | title | tier | runs ok | passed | failed | KNOWN | skipped | page |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r in reports:
        n = case_counts(r)
        page = f"{CASES_DIR}/{r.case.name}.md"
        lines.append(f"| {r.case.name} | {_md(r.case.title)} | {r.case.tier} | {n['runs_ok']}/{n['runs']} | "
                     f"{n['passed']} | {'**%d**' % n['failed'] if n['failed'] else 0} | {n['known']} | "
                     f"{n['skipped']} | [{page}]({page}) |")
    lines.append("")
    digest = stability_digest(reports_dir) if reports_dir is not None else []
    if digest:
        lines += ["## Stability limits and extreme probes", ""]
        lines += [f"- {_md(d)}" for d in digest]
        lines += ["", f"Their tables: [{STABILITY_PAGE}.md]({STABILITY_PAGE}.md).", ""]
    return "\n".join(lines) + "\n"


def _md(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def case_markdown(r, revision, date):
    """The page of one case (cases/<case>.md): every table of the case, its figures linked."""
    c = r.case
    lines = [f"# {c.name}: {c.title}", "", f"Revision `{revision}`, {date}. **{counts_text(r.verdicts)}.** "
             f"[All cases](../summary.md)", "",
             f"*Checks:* {c.checks}  ", f"*Tier:* {c.tier}; *source:* `{c.source}`", "",
             "| variant | status | wall s | steps | message |", "|---|---|---|---|---|"]
    lines += [f"| {x['variant']} | {_md(x['status'])} | {fmt_number(x['wall'])} | {fmt_number(x['steps'])} | {_md(x['message'])} |"
              for x in r.runs]
    lines.append("")
    audited = [x for x in r.runs if x.get("energy")]
    if audited:
        lines += ["Energy audit (core/energy.c):", "", "| variant | " + " | ".join(c for c, _ in ENERGY_COLUMNS) + " |",
                  "|---|" + "---|" * len(ENERGY_COLUMNS)]
        lines += [f"| {x['variant']} | " + " | ".join(fmt_number(v) for v in energy_cells(x["energy"])) + " |"
                  for x in audited]
        lines.append("")
    for f in r.figures:
        image = f"![{_md(f.title)}](../figures/{f.png.name})" if f.png else "*(no figure)*"
        lines += [f"**{_md(f.title)}**", "", image] + [f"- {_md(n)}" for n in f.notes] + [""]
        if f.paper:
            lines += [f"> {_md(f.paper)}", ""]
    lines += [f"Checks ({r.verdict_source}):", "",
              "| check | variant | value | reference | tolerance | kind | result | provenance | message |",
              "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {v.check} | {v.variant} | {fmt_number(v.value)} | {fmt_reference(v)} | {v.tolerance} | {v.kind} | "
              f"{'**FAIL**' if v.result == 'FAIL' else v.result} | {_md(v.provenance)} | {_md(v.message)} |" for v in r.verdicts]
    if not r.verdicts:
        lines.append("| *(no checks for this case)* | | | | | | | | |")
    return "\n".join(lines + [""] + _cost_markdown(r.cost)) + "\n"


def _cost_markdown(cost):
    if cost is None:
        return []
    lines = ["**Error against cost** (declared sweeps; cost = particle-steps)", ""]
    lines += [f"- {_md(m)}" for m in cost.meta]
    lines += [f"- {_md(n)}" for n in cost.notes]
    if cost.figure and cost.figure.png:
        lines += [f"![error against cost](../figures/{cost.figure.png.name})", ""]
    lines += [f"- {_md(n)}" for n in (cost.figure.notes if cost.figure else [])]
    if cost.rows:
        lines += ["", "| tolerance | cheapest setting | error | particle-steps |", "|---|---|---|---|"]
        lines += [f"| {tol:g} | {_md(sweep.setting(r)) if r else 'none of the swept settings'} | "
                  f"{fmt_number(r['error']) if r else '-'} | {fmt_number(r['particle_steps']) if r else '-'} |"
                  for tol, r in cost.cheapest.items()]
        bad = [f"{r['sweep']} x{r['factor']:g}" for r in cost.rows if sweep.failed(r)]
        if bad:
            lines += ["", f"- {UNSTABLE} (run failed, no error): {_md(', '.join(bad))}"]
    return lines + [""]


def stability_markdown(reports_dir):
    """The tables of reports/stability.tsv and extremes.tsv ('' when neither exists)."""
    lines = []
    for title, note, headers, rows in stability_tables(reports_dir):
        lines += [f"## {title}", "", note, "", "| " + " | ".join(h for _, h in headers) + " |",
                  "|" + "---|" * len(headers)]
        lines += ["| " + " | ".join(_md(r.get(k, "")) for k, _ in headers) + " |" for r in rows]
        lines.append("")
    return "\n".join(lines) + ("\n" if lines else "")


def stability_page(reports_dir, revision, date):
    """reports/stability.md: the two tables in full, or None when there are none."""
    body = stability_markdown(reports_dir)
    if not body:
        return None
    return (f"# Stability limits and extreme probes\n\nRevision `{revision}`, {date}. [All cases](summary.md)\n\n"
            + body)
