#!/usr/bin/env python3
"""README.md is the part sections of docs/sections joined by a blank line: edit those, run this."""
import pathlib

ORDER = ["00_header", "demo", "ros", "offline", "core", "core_figures", "compare", "99_footer"]
root = pathlib.Path(__file__).resolve().parent.parent
text = "\n".join((root / "docs" / "sections" / f"{name}.md").read_text() for name in ORDER)
(root / "README.md").write_text(text)
