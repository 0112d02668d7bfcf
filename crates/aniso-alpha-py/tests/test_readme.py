"""The README's Python blocks (its "Python" section) run as scripts, as a
user who saves one to a file runs it: in a folder holding the files they
name (made from the fixtures and by the CLI), each in a fresh interpreter
(Dask's local cluster starts processes that import the script). The block
that needs PDAL itself runs in test_pdal_live.py.

`python tests/test_readme.py OUT_DIR` writes the blocks to OUT_DIR as
`readme_N.py`, for `mypy --strict` (.ci/run)."""

from __future__ import annotations

import pathlib
import shutil
import subprocess
import sys
from typing import List

import pytest

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[2]
FIXTURES = REPO / "crates" / "aniso-alpha" / "tests" / "fixtures"


def python_blocks() -> List[str]:
    """The ```python blocks of the README's Python section, in order."""
    text = (REPO / "README.md").read_text()
    section = text[text.index("\n## Python\n") : text.index("\n## Performance\n")]
    blocks, inside, cur = [], False, []
    for line in section.splitlines():
        if line.strip() == "```python":
            inside, cur = True, []
        elif inside and line.strip() == "```":
            inside = False
            blocks.append("\n".join(cur) + "\n")
        elif inside:
            cur.append(line)
    return blocks


def needs_pdal(block: str) -> bool:
    return "import pdal" in block


def test_the_readme_has_its_python_blocks():
    blocks = python_blocks()
    assert len(blocks) >= 4
    assert sum(needs_pdal(b) for b in blocks) == 1
    dask = [b for b in blocks if "distributed.detect" in b]
    assert dask and all('if __name__ == "__main__":' in b for b in dask)


@pytest.fixture(scope="module")
def folder(cli, tmp_path_factory):
    """The files the README's blocks read."""
    from conftest import run_cli

    d = tmp_path_factory.mktemp("readme")
    shutil.copy(FIXTURES / "real" / "ball.ply", d / "scan.ply")
    run_cli(cli, "synth", "lines", "--seed", 1, "--output", d / "lines.xyz")
    # Two LAS/LAZ tiles side by side: the two halves of a synthetic scene.
    run_cli(cli, "synth", "planes", "--seed", 1, "--output", d / "planes.xyz")
    rows = [line for line in (d / "planes.xyz").read_text().splitlines() if line[:1] not in "#"]
    rows.sort(key=lambda r: float(r.split()[0]))
    for i, half in enumerate((rows[: len(rows) // 2], rows[len(rows) // 2 :]), start=1):
        (d / f"tile_{i}.xyz").write_text("\n".join(half) + "\n")
        run_cli(
            cli, "detect", d / f"tile_{i}.xyz", "--structure", "planes",
            "--alpha", 1, "--lambda3", 8, "--min-size", 20,
            "--output", d / f"tile_{i}.laz",
        )
    return d


@pytest.mark.parametrize("index", range(len(python_blocks())))
def test_readme_block_runs_as_a_script(folder, index):
    block = python_blocks()[index]
    if needs_pdal(block):
        pytest.skip("needs PDAL: test_pdal_live.py runs it (pytest -m pdal)")
    script = folder / f"readme_{index}.py"
    script.write_text(block)
    p = subprocess.run(
        [sys.executable, script.name], cwd=folder, capture_output=True, text=True, timeout=600
    )
    assert p.returncode == 0, f"README block {index} failed:\n{block}\n{p.stdout}\n{p.stderr}"


if __name__ == "__main__":
    out = pathlib.Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    for i, block in enumerate(python_blocks()):
        if not needs_pdal(block):
            (out / f"readme_{i}.py").write_text(block)
