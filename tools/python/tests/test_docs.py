"""docs/python.md as written: each of its ``python`` blocks run as a script and each of
its ``sh`` blocks as shell commands, in the page's order, from one temporary folder
that sees the repository's ``tools`` and ``examples`` (so that the commands' paths from
the root hold), with this interpreter as ``python``. The ``sh install`` block makes the
virtual environment these tests run in (.ci/run runs it); the ``python spark`` block runs
against the pandas stand-in for Spark in spark_standin.py. Any other info string, or a
block this test does not know how to run, fails."""

import os
import pathlib
import subprocess
import sys

import pytest

from conftest import ROOT
from doc_blocks import blocks

PAGE = ROOT / "docs" / "python.md"
HERE = pathlib.Path(__file__).resolve().parent
RUN_ELSEWHERE = {"sh install": ".ci/run makes the test's environment with it"}
BLOCKS = blocks(PAGE)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """One folder for the page's blocks, in order (a later block reads what an earlier
    one wrote, as a reader's session would)."""
    d = tmp_path_factory.mktemp("python-md")
    for name in ["tools", "examples"]:
        (d / name).symlink_to(ROOT / name)
    return d


def test_every_block_is_run():
    known = {"python", "sh", "python spark"} | set(RUN_ELSEWHERE)
    assert BLOCKS, PAGE
    unknown = [(b.line, b.info) for b in BLOCKS if b.info not in known]
    assert not unknown, f"{PAGE.name}: blocks no test runs: {unknown}"


def run(cmd, folder, **kwargs):
    env = dict(os.environ)
    env["PATH"] = f"{pathlib.Path(sys.executable).parent}{os.pathsep}{env['PATH']}"
    env["PYTHONPATH"] = os.pathsep.join(
        [str(HERE)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    return subprocess.run(cmd, cwd=folder, env=env, capture_output=True, text=True,
                          timeout=600, **kwargs)


@pytest.mark.parametrize("block", [b for b in BLOCKS if b.info not in RUN_ELSEWHERE],
                         ids=lambda b: f"line{b.line}-{b.info.replace(' ', '-')}")
def test_block_runs_as_written(block, folder):
    if block.info == "sh":
        r = run(["bash", "-euo", "pipefail", "-c", block.text], folder)
    else:
        script = block.text
        if block.info == "python spark":
            script = "from spark_standin import spark\n" + script + (
                "\nprint(summary.toPandas())\n")
        path = folder / f"block-{block.line}.py"
        path.write_text(script)
        r = run([sys.executable, str(path)], folder)
    assert r.returncode == 0, f"{PAGE.name} line {block.line}:\n{r.stdout}\n{r.stderr}"
