"""reports/summary.md: the report as markdown, from what contents.py gathered."""
from .. import sweep
from ..gate import counts_text, fmt_number, fmt_reference
from .contents import ENERGY_COLUMNS, energy_cells, stability_tables
from .cost_plot import UNSTABLE


def markdown(reports, revision, date, known_lines=()):
    """The verdict first, then the failures, then known_lines (every KNOWN discrepancy of the
    catalogue: known_list.py), then the cases."""
    verdicts = [v for r in reports for v in r.verdicts]
    lines = ["# ballast validation report", "", f"Revision `{revision}`, {date}. **{counts_text(verdicts)}.**", ""]
    failures = [v for v in verdicts if v.result == "FAIL"]
    if failures:
        lines += [f"## Failures ({len(failures)})", ""]
        lines += [f"- **FAIL** {v.case}/{v.check} ({v.variant}): {_md(v.message)}" for v in failures] + [""]
    lines += list(known_lines)
    for r in reports:
        lines += _markdown_case(r)
    return "\n".join(lines) + "\n"


def _md(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def _markdown_case(r):
    c = r.case
    lines = [f"## {c.name}: {c.title}", "", f"*Checks:* {c.checks}  ", f"*Tier:* {c.tier}; *source:* `{c.source}`", "",
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
        image = f"![{_md(f.title)}](figures/{f.png.name})" if f.png else "*(no figure)*"
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
    return lines + [""] + _cost_markdown(r.cost)


def _cost_markdown(cost):
    if cost is None:
        return []
    lines = ["**Error against cost** (declared sweeps; cost = particle-steps)", ""]
    lines += [f"- {_md(m)}" for m in cost.meta]
    lines += [f"- {_md(n)}" for n in cost.notes]
    if cost.figure and cost.figure.png:
        lines += [f"![error against cost](figures/{cost.figure.png.name})", ""]
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
    lines = []
    for title, note, headers, rows in stability_tables(reports_dir):
        lines += [f"## {title}", "", note, "", "| " + " | ".join(h for _, h in headers) + " |",
                  "|" + "---|" * len(headers)]
        lines += ["| " + " | ".join(_md(r.get(k, "")) for k, _ in headers) + " |" for r in rows]
        lines.append("")
    return "\n".join(lines) + ("\n" if lines else "")
