"""Every internal link of README.md and docs/*.md resolves.

A relative link must name a file or folder that exists, and a `#anchor` (in the same page or
in another Markdown page) must be the slug of one of that page's headings, made the way
GitHub makes it: the heading's text lower-cased, everything but letters, digits, `_`, `-`
and spaces dropped, spaces turned into `-`, and `-1`, `-2`, ... added to repeats.
Links inside code (fenced blocks and `inline code`) are not links, and web addresses are
not checked.
"""
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]

FENCE = re.compile(r"^\s*(```|~~~)")
HEADING = re.compile(r"^ {0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
INLINE_CODE = re.compile(r"`+[^`]*`+")
LINK = re.compile(r"\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]*)>?(?:\s+\"[^\"]*\")?\s*\)")


def pages():
    return [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))


def prose_lines(text):
    """The lines of a Markdown text outside fenced code blocks, with their numbers."""
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield number, line


def slug(heading):
    """GitHub's anchor for a heading's text (before repeats are numbered)."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link reads as its text
    text = text.lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(text):
    """Every anchor a Markdown page defines through its headings."""
    seen = {}
    found = set()
    for _, line in prose_lines(text):
        m = HEADING.match(line)
        if not m:
            continue
        base = slug(m.group(2))
        n = seen.get(base, 0)
        seen[base] = n + 1
        found.add(base if n == 0 else f"{base}-{n}")
    return found


def links(text):
    """(line number, target) of every Markdown link outside code; a link's text may run
    over several lines, and its line is the one where it starts."""
    lines = text.splitlines()
    prose = dict(prose_lines(text))
    kept = "\n".join(prose.get(n, "") for n in range(1, len(lines) + 1))
    kept = INLINE_CODE.sub(lambda m: "\n" * m.group(0).count("\n"), kept)
    for m in LINK.finditer(kept):
        yield kept.count("\n", 0, m.start()) + 1, m.group(1)


def broken_links(page, root=ROOT):
    """What does not resolve among the internal links of one page, one line per link."""
    text = page.read_text(encoding="utf-8")
    problems = []
    for number, target in links(text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):  # https:, mailto:, ...
            continue
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        where = f"{page.relative_to(root)}:{number}: ({target})"
        if not dest.exists():
            problems.append(f"{where} no such file")
            continue
        if anchor:
            if dest.suffix != ".md" or dest.is_dir():
                problems.append(f"{where} an anchor into a file that is not Markdown")
            elif anchor not in anchors(dest.read_text(encoding="utf-8")):
                problems.append(f"{where} no heading with anchor #{anchor}")
    return problems


def test_every_internal_link_resolves():
    problems = [p for page in pages() for p in broken_links(page)]
    assert not problems, "broken links:\n" + "\n".join(problems)


def test_readme_links_every_docs_page():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    targets = {t.partition("#")[0] for _, t in links(readme)}
    missing = [p.name for p in sorted((ROOT / "docs").glob("*.md"))
               if f"docs/{p.name}" not in targets]
    assert not missing, f"README.md does not link to docs/{missing}"


def test_slugs_are_githubs():
    assert slug("Threads (OpenMP): `make bench-threads`") == "threads-openmp-make-bench-threads"
    assert slug("Exact static solver (MLH Sec. 4.2)") == "exact-static-solver-mlh-sec-42"
    assert slug("Matuttis, Luding & Herrmann (2000), Sec. 2.1") == \
        "matuttis-luding--herrmann-2000-sec-21"
    assert slug("Order of accuracy in Δt") == "order-of-accuracy-in-δt"
    assert slug("A reference: `reference/<family>.ref`") == "a-reference-referencefamilyref"
    assert anchors("# A\n## B\n```\n## C\n```\n## B\n") == {"a", "b", "b-1"}


def test_a_broken_link_is_found(tmp_path):
    (tmp_path / "other.md").write_text("# Other page\n\n## Its section\n")
    page = tmp_path / "page.md"
    page.write_text(
        "# Page\n\n"
        "[fine](other.md#its-section) [fine](#page) [web](https://example.org/x#y)\n"
        "`[in code](nowhere.md)`\n"
        "```\n[in a fence](nowhere.md)\n```\n"
        "[gone](missing.md) [bad anchor](other.md#no-such) [here](#nothing)\n"
        "and [a link over\ntwo lines](other.md#its-section), [another\none](#none)\n")
    problems = broken_links(page, root=tmp_path)
    assert [p.split(" ", 1)[0] for p in problems] == ["page.md:8:"] * 3 + ["page.md:10:"]
    assert "(missing.md) no such file" in problems[0]
    assert "#no-such" in problems[1] and "#nothing" in problems[2] and "#none" in problems[3]
