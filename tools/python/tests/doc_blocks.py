"""The fenced blocks of a Markdown page by their info string: what the docs tests run.

    python tools/python/tests/doc_blocks.py docs/python.md "sh install"

prints the blocks of that info string (for a shell to run, as .ci/run does). A block's
info string is the text after its opening fence: ``python``, ``sh``, ``sh install``,
``python spark``.
"""

import pathlib
import re
import sys
from typing import List, NamedTuple

_FENCE = re.compile(r"^(`{3,})([^`\n]*)\n(.*?)^\1[ \t]*$", re.M | re.S)


class Block(NamedTuple):
    info: str
    line: int  # of the opening fence, 1-based
    text: str


def blocks(path) -> List[Block]:
    """Every fenced block of the page, in order."""
    text = pathlib.Path(path).read_text()
    return [Block(m.group(2).strip(), text.count("\n", 0, m.start()) + 1, m.group(3))
            for m in _FENCE.finditer(text)]


if __name__ == "__main__":
    page, info = sys.argv[1], sys.argv[2]
    found = [b.text for b in blocks(page) if b.info == info]
    if not found:
        sys.exit(f"{page}: no block with the info string {info!r}")
    print("\n".join(found), end="")
