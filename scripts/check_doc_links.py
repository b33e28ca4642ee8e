#!/usr/bin/env python3
"""Every relative link of README.md and docs/*.md names a file of the repository (ctest entry
docs_links; issue 41: docs/demo_report.md linked three images of demo_output/ that docs/ does not
hold). Links with a scheme (https:, mailto:) and in-page anchors are not checked.
Usage: check_doc_links.py REPOSITORY_ROOT"""
import glob
import os
import re
import sys

root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
files = [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md")))
link = re.compile(r"\]\(([^)\s]+)\)")
missing = 0
for path in files:
    with open(path, encoding="utf-8") as f:
        text = f.read()
    # Code spans and blocks hold text, not links.
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)
    for m in link.finditer(text):
        target = m.group(1).split("#", 1)[0]
        if not target or re.match(r"[a-zA-Z][a-zA-Z0-9+.-]*:", target):
            continue
        if not os.path.exists(os.path.normpath(os.path.join(os.path.dirname(path), target))):
            print(f"{os.path.relpath(path, root)}: link to a missing file: {m.group(1)}")
            missing += 1
print(f"check_doc_links: {len(files)} files, {missing} missing link target(s)")
sys.exit(1 if missing else 0)
