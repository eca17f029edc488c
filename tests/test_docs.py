"""The documentation is checked against the code where it quotes it: the case keys it names
exist, the commands it shows parse, and its Python example runs."""

import re
import shlex
from pathlib import Path

import pytest

from taichi_sls.cli import parser
from taichi_sls.config import Case

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
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


@pytest.mark.parametrize("doc", DOCS, ids=[p.name for p in DOCS])
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


@pytest.mark.parametrize("doc", DOCS, ids=[p.name for p in DOCS])
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
