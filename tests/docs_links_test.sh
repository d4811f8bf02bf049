#!/usr/bin/env bash
# Checks the documentation: every relative link and image in README.md, ARCHITECTURE.md and
# docs/**/*.md resolves to an existing file inside the repository (and, for a link into a
# Markdown file with #anchor, to one of its headings); no link leaves the repository except
# http(s) links to web pages; README.md has at most 220 lines; and every line of a code block
# marked `<!-- snippet-of: PATH -->` is in PATH (whitespace, trailing `;` and `//` comments
# aside), so that the README's program stays the one tests/install_test.sh builds.
# Arguments: <conform binary> <source dir> <build dir> (only the source dir is used).
set -euo pipefail
source_dir="${2:?usage: docs_links_test.sh CONFORM SOURCE_DIR BUILD_DIR}"
exec /usr/bin/python3 - "$source_dir" <<'PYEOF'
import os
import re
import sys

root = os.path.realpath(sys.argv[1])
max_readme_lines = 220
errors = []

files = [os.path.join(root, "README.md"), os.path.join(root, "ARCHITECTURE.md")]
for folder, _, names in os.walk(os.path.join(root, "docs")):
    files += [os.path.join(folder, n) for n in sorted(names) if n.endswith(".md")]

fence = re.compile(r"^\s*(```|~~~)")


def prose_lines(text):
    """The lines outside fenced code blocks, with inline code spans blanked."""
    out, inside = [], False
    for line in text.split("\n"):
        if fence.match(line):
            inside = not inside
            out.append("")
            continue
        out.append("" if inside else re.sub(r"`[^`]*`", "``", line))
    return out


def slug(heading):
    s = re.sub(r"`", "", heading.strip().lower())
    s = re.sub(r"[^\w\- ]", "", s)
    return s.replace(" ", "-")


anchors_cache = {}


def anchors(path):
    if path not in anchors_cache:
        seen, result = {}, set()
        text = open(path, encoding="utf-8").read()
        inside = False
        for line in text.split("\n"):
            if fence.match(line):
                inside = not inside
                continue
            m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
            if m and not inside:
                base = slug(m.group(1))
                n = seen.get(base, 0)
                seen[base] = n + 1
                result.add(base if n == 0 else f"{base}-{n}")
        anchors_cache[path] = result
    return anchors_cache[path]


link = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]*)>?(?:\s+\"[^\"]*\")?\s*\)")
image_tag = re.compile(r"<img\s[^>]*src=\"([^\"]+)\"", re.I)
reference = re.compile(r"^[ \t]*\[[^\]]+\]:[ \t]*(\S+)", re.M)

checked = 0
for md in files:
    rel_md = os.path.relpath(md, root)
    text = open(md, encoding="utf-8").read()
    prose = "\n".join(prose_lines(text))
    found = [(m.start(), m.group(1)) for m in link.finditer(prose)]  # a link may wrap lines
    found += [(m.start(), m.group(1)) for m in image_tag.finditer(prose)]
    found += [(m.start(), m.group(1)) for m in reference.finditer(prose)]
    for position, target in sorted(found):
        number = prose.count("\n", 0, position) + 1
        checked += 1
        where = f"{rel_md}:{number}: link '{target}'"
        if re.match(r"^https?://", target):
            continue
        if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target) or target.startswith("//"):
            errors.append(f"{where} leaves the repository (only http(s) links may)")
            continue
        path, _, anchor = target.partition("#")
        if path.startswith("/"):
            errors.append(f"{where} is absolute: links must be relative to the file")
            continue
        resolved = os.path.realpath(os.path.join(os.path.dirname(md), path)) if path else md
        if resolved != root and not resolved.startswith(root + os.sep):
            errors.append(f"{where} resolves outside the repository ({resolved})")
            continue
        if not os.path.exists(resolved):
            errors.append(f"{where}: {os.path.relpath(resolved, root)} does not exist")
            continue
        if anchor and resolved.endswith(".md") and anchor not in anchors(resolved):
            errors.append(f"{where}: no heading #{anchor} in {os.path.relpath(resolved, root)}")

    # Code blocks that must stay copies of a source file.
    lines = text.split("\n")
    for i, line in enumerate(lines):
        m = re.match(r"^\s*<!--\s*snippet-of:\s*(\S+)\s*-->\s*$", line)
        if not m:
            continue
        source = os.path.join(root, m.group(1))
        if not os.path.isfile(source):
            errors.append(f"{rel_md}:{i + 1}: snippet source {m.group(1)} does not exist")
            continue
        if i + 1 >= len(lines) or not fence.match(lines[i + 1]):
            errors.append(f"{rel_md}:{i + 1}: snippet marker not followed by a code block")
            continue
        squash = lambda s: re.sub(r"\s+", "", s)
        body = squash(open(source, encoding="utf-8").read())
        j = i + 2
        while j < len(lines) and not fence.match(lines[j]):
            code = squash(re.sub(r"//.*$", "", lines[j])).rstrip(";")
            if code and code not in body:
                errors.append(f"{rel_md}:{j + 1}: not in {m.group(1)}: {lines[j].strip()}")
            j += 1

readme = os.path.join(root, "README.md")
readme_lines = open(readme, encoding="utf-8").read().count("\n")
if readme_lines > max_readme_lines:
    errors.append(f"README.md has {readme_lines} lines, more than {max_readme_lines}: move detail to docs/")
if "snippet-of:" not in open(readme, encoding="utf-8").read():
    errors.append("README.md has no <!-- snippet-of: ... --> program")

for e in errors:
    print("docs_links_test: " + e, file=sys.stderr)
print(f"docs_links_test: {len(files)} files, {checked} links, README.md {readme_lines} lines, "
      f"{len(errors)} problems")
sys.exit(1 if errors else 0)
PYEOF
