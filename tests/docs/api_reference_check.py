"""Keeps the API reference (docs/api/*.md) in step with the public headers (include/bvhkit).

Checks, naming every miss:
1. every public header is named in the reference (by its path under include/bvhkit/);
2. every class, struct, enum, alias and concept declared directly in namespace bvhkit (not in a
   detail namespace, not nested in a class) is named in the reference;
3. the reference's list of what bvhkit.hpp includes is exactly what it includes.

Run as `python3 tests/docs/api_reference_check.py ROOT`; ctest runs it (test `api_reference`).
"""

import pathlib
import re
import sys

DECLARATION = re.compile(
    r"^\s*(?:template\s*<[^;{]*>\s*)?"
    r"(?:(?:struct|class|union)\s+(?:alignas\([^)]*\)\s*)?(\w+)\s*(?:final\s*)?[:{]"
    r"|enum\s+(?:class\s+|struct\s+)?(\w+)\s*[:{]"
    r"|using\s+(\w+)\s*="
    r"|concept\s+(\w+)\s*=)"
)


def strip_comments_and_strings(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'R"\((.*?)\)"', '""', text, flags=re.S)
    text = re.sub(r'"(?:\\.|[^"\\\n])*"', '""', text)
    return re.sub(r"'(?:\\.|[^'\\\n])'", "''", text)


def public_names(header_text):
    """Names declared at namespace bvhkit's own scope, line by line with a brace stack."""
    names = set()
    stack = []  # one entry per open brace: a namespace name, or None for any other block
    for line in strip_comments_and_strings(header_text).splitlines():
        if stack == ["bvhkit"]:
            m = DECLARATION.match(line)
            if m:
                names.add(next(g for g in m.groups() if g))
        for token in re.finditer(r"namespace\s+([\w:]+)\s*\{|\{|\}", line):
            if token.group(0) == "}":
                if stack:
                    stack.pop()
            elif token.group(1):
                # `namespace a::b {` opens one brace: one entry, named for the innermost namespace.
                stack.append(token.group(1) if "::" not in token.group(1) else None)
            else:
                stack.append(None)
    return names


def main(root):
    root = pathlib.Path(root)
    include = root / "include" / "bvhkit"
    reference = "\n".join(p.read_text() for p in sorted((root / "docs" / "api").glob("*.md")))
    problems = []

    headers = sorted(include.rglob("*.hpp"))
    for header in headers:
        relative = header.relative_to(include).as_posix()
        if relative not in reference:
            problems.append(f"header {relative} is not named in docs/api/")

    for header in headers:
        for name in sorted(public_names(header.read_text())):
            if not re.search(r"\b" + re.escape(name) + r"\b", reference):
                relative = header.relative_to(include).as_posix()
                problems.append(f"{name} (declared in {relative}) is not named in docs/api/")

    umbrella = (include / "bvhkit.hpp").read_text()
    included = set(re.findall(r'#include\s*[<"]bvhkit/([\w/.]+)[>"]', umbrella))
    top = (root / "docs" / "api" / "top-level.md").read_text()
    section = re.search(r"## `bvhkit.hpp`\n(.*?)\n## ", top, flags=re.S)
    if not section:
        problems.append("docs/api/top-level.md has no '## `bvhkit.hpp`' section")
    else:
        listed = {h.removeprefix("bvhkit/") for h in re.findall(r"`([\w/]+\.hpp)`", section.group(1))}
        listed.discard("bvhkit.hpp")
        for h in sorted(included - listed):
            problems.append(f"bvhkit.hpp includes {h}, which top-level.md's list leaves out")
        for h in sorted(listed - included):
            problems.append(f"top-level.md says bvhkit.hpp includes {h}; it does not")

    for p in problems:
        print(p)
    print(f"api_reference: {len(headers)} headers checked, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
