"""Every command and snippet of docs/modbus.md, run as the page shows it (`cargo xtask
modbus` runs this file after the nodes' tests; it boots its own nodes, through the
page's own commands).

The page's fenced blocks, by their info string, in the page's order:

- `sh`: run by bash (`set -e`), in a scratch folder inside the checkout
  (target/docs-modbus) that links the checkout's `tools`, `examples` and `docs`, so
  that the page's relative paths and cargo work as in the checkout's root, and the
  files the page writes stay out of it;
- `sh serve`: a command that serves until stopped ("in one terminal", the page says):
  every such block starts first, in the background, and is waited for until it
  serves; stopped at the end;
- `python`: run by this Python (the tests' virtual environment, with pymodbus);
- `text output`: what the block before it prints, line for line;
- any other (`rust,ignore`, ...): not this file's.

The page's TCP ports (5020, 5021) stand for free ports picked here. The commands run
with this environment's `python3` and `pip` first on the PATH; the page's `pip
install` pins are checked against what is installed before it runs.
"""

import importlib.metadata
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "modbus.md"


def blocks(page):
    """The fenced blocks of a Markdown page: (info words, text, line of the fence)."""
    lines = page.read_text().splitlines()
    out, i = [], 0
    while i < len(lines):
        fence = re.match(r"^```(.*)$", lines[i])
        if not fence:
            i += 1
            continue
        end = next(k for k in range(i + 1, len(lines)) if lines[k] == "```")
        out.append((fence.group(1).split(), "\n".join(lines[i + 1:end]) + "\n", i + 1))
        i = end + 1
    return out


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def scratch():
    """The folder the page's commands run in: fresh, the checkout's paths linked."""
    d = ROOT / "target" / "docs-modbus"
    shutil.rmtree(d, ignore_errors=True)
    d.mkdir(parents=True)
    for name in ("tools", "examples", "docs"):
        (d / name).symlink_to(ROOT / name)
    return d


def environment():
    env = dict(os.environ)
    env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + env["PATH"]
    return env


class Served:
    """A `sh serve` block in the background, its output read until it serves."""

    def __init__(self, text, cwd, line):
        self.line = line
        self.proc = subprocess.Popen(["bash", "-c", text], cwd=cwd, env=environment(),
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, start_new_session=True)
        self.serving = threading.Event()
        self.log = []
        threading.Thread(target=self.read, daemon=True).start()

    def read(self):
        for out in self.proc.stdout:
            self.log.append(out)
            if out.startswith("serving on"):
                self.serving.set()

    def wait(self, timeout):
        start = time.monotonic()
        while not self.serving.wait(1):
            assert self.proc.poll() is None, f"line {self.line}: stopped\n{''.join(self.log)}"
            assert time.monotonic() - start < timeout, f"line {self.line}: did not serve"

    def stop(self):
        # The shell's session: cargo and xtask, whose QEMU stops with it.
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
        self.proc.wait(timeout=60)


def check_pins(text, line):
    """The page's `pip install` pins are the versions installed here (CI's)."""
    for name, version in re.findall(r"([A-Za-z][\w.-]*)==([\w.]+)", text):
        assert importlib.metadata.version(name) == version, f"line {line}: {name}=={version}"


def test_every_block_of_the_page_runs_as_shown():
    page = blocks(PAGE)
    ports = {}
    for info, text, _ in page:
        if info[:2] == ["sh", "serve"]:
            for port in re.findall(r"--serve (\d+)", text):
                ports[port] = str(free_port())

    def local(text):
        for page_port, port in ports.items():
            text = re.sub(rf"\b{page_port}\b", port, text)
        return text

    cwd = scratch()
    served = [Served(local(text), cwd, line) for info, text, line in page
              if info[:2] == ["sh", "serve"]]
    ran = 0
    try:
        for s in served:
            s.wait(timeout=1200)
        last = None
        for info, text, line in page:
            if info == ["sh"]:
                check_pins(text, line)
                done = subprocess.run(["bash", "-e", "-c", local(text)], cwd=cwd,
                                      env=environment(), capture_output=True, text=True,
                                      timeout=1800)
            elif info == ["python"]:
                done = subprocess.run([sys.executable, "-c", local(text)], cwd=cwd,
                                      env=environment(), capture_output=True, text=True,
                                      timeout=600)
            elif info == ["text", "output"]:
                assert last is not None, f"line {line}: no block before it"
                assert last.stdout.splitlines() == text.splitlines(), \
                    f"line {line}: the block before it printed\n{last.stdout}"
                continue
            else:
                continue
            assert done.returncode == 0, f"line {line}:\n{text}\n{done.stdout}{done.stderr}"
            last = done
            ran += 1
    finally:
        for s in served:
            s.stop()
    assert len(served) == 2 and ran >= 6, (len(served), ran)
