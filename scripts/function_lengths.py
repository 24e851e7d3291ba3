#!/usr/bin/env python3
"""Lines per function body in C++ sources, longest first.

usage: function_lengths.py [--max N] [PATH...]   (default: src apps, N 60)

A function is a brace block opened, outside any other function, after a
parameter list: free functions, member functions (in or out of their class),
lambdas at namespace scope. Its length is the lines from the line of its `{`
to the line of its `}`, both counted. Strings, characters and comments are
skipped. Exit status 1 when a function is longer than N lines.
"""
import argparse
import pathlib
import re
import sys

TYPE_RE = re.compile(r"\b(class|struct|union|enum)\b[^()]*$")
NAMESPACE_RE = re.compile(r"\bnamespace\b[^()]*$|extern\s+\"C\+*\"\s*$")


def strip(text):
    """The source with comments, strings and characters blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
        elif c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
            out.append(c)  # a digit separator (10'000)
            i += 1
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """(name, first line, lines) of each function in `path`."""
    text = strip(path.read_text(errors="replace"))
    stack, found, head, line = [], [], "", 1
    for c in text:
        if c == "\n":
            line += 1
        if c == "{":
            kind = "block"
            in_function = any(k == "function" for k, _, _ in stack)
            h = head.strip()
            if not in_function:
                if NAMESPACE_RE.search(h):
                    kind = "namespace"
                elif TYPE_RE.search(h):
                    kind = "type"
                elif ")" in h and not h.endswith("="):
                    kind = "function"
            name = re.sub(r"\s+", " ", h.split("(")[0])[-60:] if kind == "function" else ""
            stack.append((kind, line, name))
            head = ""
        elif c == "}":
            if stack:
                kind, start, name = stack.pop()
                if kind == "function":
                    found.append((name, start, line - start + 1))
            head = ""
        elif c == ";":
            head = ""
        else:
            head += c
    return found


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--max", type=int, default=60)
    parser.add_argument("paths", nargs="*", default=["src", "apps"])
    args = parser.parse_args()
    rows = []
    for root in args.paths:
        for path in sorted(pathlib.Path(root).rglob("*")):
            if path.suffix in (".cpp", ".hpp", ".h", ".cc"):
                rows += [(n, str(path), s, name) for name, s, n in functions(path)]
    rows.sort(reverse=True)
    over = [r for r in rows if r[0] > args.max]
    for n, path, start, name in over:
        print(f"{n:4d} lines  {path}:{start}  {name}")
    print(f"{len(rows)} functions, {len(over)} over {args.max} lines")
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
