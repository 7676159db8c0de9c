#!/usr/bin/env python3
"""Fails when a function in the given folders is longer than its limit.

Usage: function_lengths.py ROOT [--limit N] [--step-limit N] FOLDER...
Every function body (from its opening brace's line to its closing brace's) in the .hpp, .cpp, .cu
and .cuh files under ROOT/FOLDER is at most --limit lines (150); a function named `step` at most
--step-limit (80). Bodies are found by matching braces in the text with comments, strings and
character literals blanked out; a brace opens a function when, outside any function, the text
before it ends in a parameter list (and qualifiers or an initializer list) and is no class,
namespace, enum or control statement. Lambdas and local classes count toward their function.
"""
import argparse
import os
import re
import sys

KEYWORDS = ("namespace", "class", "struct", "union", "enum", "extern")
CONTROL = ("if", "for", "while", "switch", "catch", "do", "else", "try")


def blank(text):
    """Comments, string and character literals replaced by spaces, newlines kept."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i) and re.match(r'R"([^(]*)\(', text[i:]):
            delim = re.match(r'R"([^(]*)\(', text[i:]).group(1)
            end = text.find(")" + delim + '"', i)
            end = n if end < 0 else end + len(delim) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (min(j + 1, n) - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def opens_function(header):
    """Whether the text between the last ; { } and a brace is a function's signature."""
    h = " ".join(header.split())
    if not h or ")" not in h:
        return False
    first = re.match(r"[A-Za-z_]+", h.lstrip("~"))
    word = first.group(0) if first else ""
    if word in KEYWORDS or word in CONTROL or h.startswith("#"):
        return False
    if re.search(r"\b(class|struct|union|enum|namespace)\b[^()]*$", h):
        return False
    if h.rstrip().endswith("=") or re.search(r"=\s*\[[^\]]*\]\s*(\([^)]*\))?\s*(mutable)?$", h):
        return False  # a variable's initializer, or a lambda assigned at namespace scope
    return True


def functions(path):
    text = blank(open(path, encoding="utf-8", errors="replace").read())
    line = 1
    depth = 0               # braces open
    function_depth = None   # depth at which the current function's body opened
    start_line = 0
    header_start = 0
    name = ""
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        elif c == "{":
            if function_depth is None and opens_function(text[header_start:i]):
                function_depth = depth
                start_line = line
                m = re.findall(r"([~A-Za-z_][A-Za-z_0-9:<>~]*)\s*\(", text[header_start:i])
                name = m[0] if m else "?"
            depth += 1
            header_start = i + 1
        elif c == "}":
            depth -= 1
            if function_depth is not None and depth == function_depth:
                yield name, start_line, line
                function_depth = None
            header_start = i + 1
        elif c == ";":
            header_start = i + 1


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("root")
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--limit", type=int, default=150)
    parser.add_argument("--step-limit", type=int, default=80)
    args = parser.parse_args()
    failures, counted, longest = [], 0, (0, "")
    for folder in args.folders:
        for directory, _, files in os.walk(os.path.join(args.root, folder)):
            for f in sorted(files):
                if not f.endswith((".hpp", ".cpp", ".cu", ".cuh")):
                    continue
                path = os.path.join(directory, f)
                for name, first, last in functions(path):
                    counted += 1
                    length = last - first + 1
                    where = f"{os.path.relpath(path, args.root)}:{first} {name} ({length} lines)"
                    longest = max(longest, (length, where))
                    limit = args.step_limit if name.split("::")[-1] == "step" else args.limit
                    if length > limit:
                        failures.append(f"{where}, more than {limit}")
    if counted == 0:
        print("function_lengths: no function found: the scan is broken")
        return 1
    for f in failures:
        print("function_lengths:", f)
    print(f"function_lengths: {counted} functions, the longest {longest[1]}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
