#!/usr/bin/env python3
"""Checks the repository's own references to its documents.

    check_links.py SOURCE_DIR

1. Every relative link in the Markdown files (README.md, docs/, examples/,
   samples/) names a file or folder that exists, and a link with an anchor
   into a Markdown file names one of its headings (GitHub's anchors:
   lower case, punctuation dropped, spaces as hyphens).
2. Every docs/ path cited in the code's comments (glint/, shaders/,
   samples/, tests/, scripts/, cmake/) exists.

Prints each broken reference as FILE:LINE: what, and exits 1 if any.
"""
import os
import re
import sys

MARKDOWN_DIRS = ("docs", "examples", "samples")
CODE_DIRS = ("glint", "shaders", "samples", "tests", "scripts", "cmake")
CODE_SUFFIXES = (".h", ".cpp", ".glsl", ".comp", ".rgen", ".rchit", ".rmiss", ".rahit", ".vert", ".frag",
                 ".py", ".sh", ".cmake", ".txt", "")
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
DOC_PATH = re.compile(r"(?<![\w/.-])docs/[A-Za-z0-9_./-]*[A-Za-z0-9_/]")


def anchor(heading):
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


_anchors = {}  # Markdown file -> its headings' anchors


def anchors(path):
    if path not in _anchors:
        found = set()
        in_code = False
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.startswith("```"):
                    in_code = not in_code
                elif not in_code and line.startswith("#"):
                    found.add(anchor(line.lstrip("#")))
        _anchors[path] = found
    return _anchors[path]


def markdown_files(root):
    yield os.path.join(root, "README.md")
    for top in MARKDOWN_DIRS:
        for base, dirs, files in os.walk(os.path.join(root, top)):
            dirs[:] = sorted(d for d in dirs if not d.startswith("."))
            for name in sorted(files):
                if name.endswith(".md"):
                    yield os.path.join(base, name)


def check_markdown(root, path, problems):
    in_code = False
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            if line.startswith("```"):
                in_code = not in_code
            if in_code:
                continue
            for target in LINK.findall(line):
                if re.match(r"^[a-z]+:", target):
                    continue  # https:, mailto: and the like
                file_part, _, fragment = target.partition("#")
                resolved = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) if file_part else path
                where = f"{os.path.relpath(path, root)}:{number}"
                if not os.path.exists(resolved):
                    problems.append(f"{where}: link to {target}: no such file")
                elif fragment and resolved.endswith(".md") and fragment not in anchors(resolved):
                    problems.append(f"{where}: link to {target}: no heading with that anchor")


def check_code(root, problems):
    for top in CODE_DIRS:
        for base, dirs, files in os.walk(os.path.join(root, top)):
            dirs[:] = sorted(d for d in dirs if not d.startswith("."))
            for name in sorted(files):
                if os.path.splitext(name)[1] not in CODE_SUFFIXES:
                    continue
                path = os.path.join(base, name)
                try:
                    with open(path, encoding="utf-8") as f:
                        lines = f.readlines()
                except UnicodeDecodeError:
                    continue
                for number, line in enumerate(lines, 1):
                    for cited in DOC_PATH.findall(line):
                        if not os.path.exists(os.path.join(root, cited.rstrip("/"))):
                            problems.append(f"{os.path.relpath(path, root)}:{number}: cites {cited}: no such file")


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[0], file=sys.stderr)
        print("usage: check_links.py SOURCE_DIR", file=sys.stderr)
        return 2
    root = os.path.abspath(argv[1])
    problems = []
    count = 0
    for path in markdown_files(root):
        if os.path.exists(path):
            count += 1
            check_markdown(root, path, problems)
    check_code(root, problems)
    for p in problems:
        print(p)
    print(f"check_links: {count} Markdown files, {len(problems)} broken references")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
