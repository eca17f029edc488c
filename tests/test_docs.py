"""The documentation is checked against the code where it quotes it: the case keys it names
exist, the commands it shows parse, and its Python example runs; and against itself: every
relative link and picture of the README and of docs/ (the guide and docs/record/) resolves, and
every doc page the code names exists."""

import re
import shlex
from pathlib import Path

import pytest

from taichi_sls.cli import parser
from taichi_sls.config import Case

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
DOC_IDS = [str(p.relative_to(ROOT)) for p in DOCS]
SECTIONS = set(Case.model_fields)
FILE_TYPES = {"toml", "csv", "json", "png", "md", "txt", "gif", "npz", "py", "vtu", "pvd"}


def _keys(text: str) -> set[str]:
    """`section.key` names in backticks whose section is a case table."""
    found = set()
    for m in re.finditer(r"`([a-z_]+)\.([a-z_0-9]+)(?:\.[a-z_0-9]+)?(?: = [^`]*)?`", text):
        if m.group(1) in SECTIONS and m.group(2) not in FILE_TYPES:
            found.add((m.group(1), m.group(2)))
    return found


def _known(section: str, key: str) -> bool:
    from taichi_sls.config import Bed, Disc, Material, Polygon, Rect
    from taichi_sls.config.sections import Laser, Wall

    ann = Case.model_fields[section].annotation
    models = {
        "bodies": (Disc, Rect, Polygon),
        "materials": (Material,),
        "lasers": (Laser,),
        "boundary": (Wall,),
        "bed": (Bed,),
    }.get(section, (ann,))
    if section == "boundary" and key in ("left", "right", "bottom", "top", "front", "back"):
        return True
    if section in ("materials", "lasers", "bodies") and (key.isdigit() or key.isupper()):
        return True
    return any(key in m.model_fields for m in models)


@pytest.mark.parametrize("doc", DOCS, ids=DOC_IDS)
def test_every_case_key_the_docs_name_exists(doc):
    missing = [f"{s}.{k}" for s, k in _keys(doc.read_text()) if not _known(s, k)]
    assert not missing, f"{doc.name} names keys the schema does not have: {missing}"


def _commands(text: str) -> list[list[str]]:
    out = []
    for block in re.findall(r"```(?:bash|sh)\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            line = line.split("#", 1)[0].strip()
            for part in line.split("&&"):
                words = shlex.split(part.strip()) if part.strip() else []
                if words[:1] == ["taichi-sls"]:
                    out.append(words[1:])
                elif words[:3] == ["python", "-m", "taichi_sls.run"]:
                    out.append(["run", *words[3:]])
    return out


@pytest.mark.parametrize("doc", DOCS, ids=DOC_IDS)
def test_every_command_the_docs_show_parses(doc):
    for words in _commands(doc.read_text()):
        if any(c in w for w in words for c in "[]|") or "..." in words:
            continue  # a usage line, not a command
        try:
            parser().parse_args(words)
        except SystemExit as e:
            raise AssertionError(f"{doc.name}: taichi-sls {' '.join(words)} does not parse") from e


def test_the_python_api_example_runs(tmp_path, monkeypatch):
    text = (ROOT / "docs" / "running.md").read_text()
    code = re.search(r"## The Python API\n\n```python\n(.*?)```", text, flags=re.S).group(1)
    # the example as written, to 20 us and 50 steps: the API it shows is what is checked, not
    # the run's length (the fine pair's 4,000 steps to 2e-4 s cost a minute of the suite)
    code, n = re.subn(r"time\.end_s=[0-9.e+-]+", "time.end_s=2e-5", code)
    assert n == 1, "docs/running.md's example sets no time.end_s: it would run to 1 ms"
    code = re.sub(r"sim\.advance_to\([0-9.e+-]+\)", "sim.advance_to(2.5e-6)", code)  # 50 steps
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "running.md", "exec"), {})
    assert (tmp_path / "out" / "p15" / "summary.json").is_file()


def _prose(text: str) -> str:
    """The text outside fenced code blocks and inline code spans: what GitHub renders as links
    and headings."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    return re.sub(r"`[^`\n]*`", "", text)


def _anchor(heading: str) -> str:
    """GitHub's anchor for a heading: the text of its inline markup, lower case, every character
    but letters, digits, spaces, hyphens and underscores dropped, spaces made hyphens."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip())
    return re.sub(r"[^\w\- ]", "", text.lower()).replace(" ", "-")


def _anchors(page: Path) -> set[str]:
    """Every anchor of a page's headings, a repeated one suffixed -1, -2, ... as GitHub does."""
    text = re.sub(r"^```.*?^```", "", page.read_text(), flags=re.S | re.M)
    seen: dict[str, int] = {}
    out = set()
    for heading in re.findall(r"^#{1,6} +(.+?) *#*$", text, flags=re.M):
        base = _anchor(heading)
        n = seen.get(base, 0)
        seen[base] = n + 1
        out.add(base if n == 0 else f"{base}-{n}")
    return out


def _links(doc: Path) -> list[tuple[bool, str]]:
    """(is a picture, target) of every Markdown link of a page outside code."""
    found = re.findall(r"(!?)\[[^\]]*\]\(([^)\s]+)(?: \"[^\"]*\")?\)", _prose(doc.read_text()))
    return [(bang == "!", target) for bang, target in found]


def test_the_anchor_rule_is_githubs():
    assert _anchor("The solid's stiffness") == "the-solids-stiffness"
    assert (
        _anchor("The process cycle: a hatched layer held")
        == "the-process-cycle-a-hatched-layer-held"
    )
    assert (
        _anchor("A pair in the window (`cases/pair_window.toml`, `taichi-sls bench window`)")
        == "a-pair-in-the-window-casespair_windowtoml-taichi-sls-bench-window"
    )
    assert _anchor("3D beds: spheres") == "3d-beds-spheres"


@pytest.mark.parametrize("doc", DOCS, ids=DOC_IDS)
def test_every_relative_link_resolves(doc):
    """Each relative link names a file that exists (from the page's folder) and, where it has
    an #anchor, a heading of that page; each picture is a file. Web links are not fetched."""
    broken = []
    for picture, target in _links(doc):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):
            continue  # http:, https:, mailto:
        path, _, anchor = target.partition("#")
        page = (doc.parent / path).resolve() if path else doc
        if not page.exists():
            broken.append(f"{target} (no such file)")
        elif picture and not page.is_file():
            broken.append(f"{target} (a picture that is not a file)")
        elif anchor and page.suffix == ".md" and anchor not in _anchors(page):
            broken.append(f"{target} (no heading #{anchor} in {page.name})")
    assert not broken, f"{doc.relative_to(ROOT)} links to what is not there: {broken}"


@pytest.mark.parametrize("doc", DOCS, ids=DOC_IDS)
def test_every_figure_and_table_path_it_names_exists(doc):
    """Paths written out in the text (`renders/x.png`, docs/record/data/x.csv), not as links:
    the pictures in renders/ and the tables in docs/record/data/ they name exist (a table a
    command writes into renders/ is its output, not a committed file)."""
    picture = r"renders/[\w.-]+\.(?:png|gif)"
    table = r"docs/record/data/[\w.-]+\.\w+"
    named = re.findall(rf"(?<![\w/.])({picture}|{table})", doc.read_text())
    missing = sorted({p for p in named if not (ROOT / p).exists()})
    assert not missing, f"{doc.relative_to(ROOT)} names files that do not exist: {missing}"


def test_every_doc_page_the_code_names_exists():
    """Docstrings, messages, schema descriptions and case-file comments point at doc pages
    (docs/record/beds.md, ...): each one exists."""
    sources = [
        *(ROOT / "taichi_sls").rglob("*.py"),
        *(ROOT / "taichi_sls").rglob("*.toml"),
        *(ROOT / "tests").rglob("*.py"),
        *(ROOT / "bench").rglob("*.py"),  # one-off benchmarks, where the checkout has them
        ROOT / "pyproject.toml",
    ]
    missing = sorted(
        f"{source.relative_to(ROOT)}: {name}"
        for source in sources
        for name in set(re.findall(r"(?<![\w/.])docs/[\w/]+\.md", source.read_text()))
        if not (ROOT / name).is_file()
    )
    assert not missing, f"the code names doc pages that do not exist: {missing}"
