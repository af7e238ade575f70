#!/usr/bin/env python3
"""Fails when a function of the layers is too long or takes too many parameters.

Scans the .cc files of lidar/, colmap_ext/ and bridge/ (not the unit tests beside them) for
function definitions at namespace scope (Google style: the body's closing brace at column 0) and
prints every definition whose body is longer than --max-lines lines or whose parameter list has
more than --max-parameters parameters, as file:line. Exits 1 if there is any.
  scripts/check_functions.py [--max-lines 60] [--max-parameters 6] [ROOT]
"""
import argparse
import pathlib
import re
import sys

LAYERS = ("lidar", "colmap_ext", "bridge")
# String and character literals and line comments, which may hold braces or parentheses.
NOISE = re.compile(r'"(?:[^"\\]|\\.)*"|\'(?:[^\'\\]|\\.)*\'|//.*')


def parameter_count(signature):
    """Parameters of the first parenthesised list outside template brackets in `signature`."""
    angle = 0
    for start, char in enumerate(signature):
        if char == "<":
            angle += 1
        elif char == ">":
            angle = max(0, angle - 1)
        elif char == "(" and angle == 0:
            break
    else:
        return 0
    depth, count, inside = 0, 0, ""
    for char in signature[start:]:
        if char in "(<[{":
            depth += 1
        elif char in ")>]}":
            depth -= 1
            if depth == 0:
                break
        if depth == 1 and char == ",":
            count += 1
        if depth >= 1:
            inside += char
    inside = inside[1:].strip()
    if not inside or inside == "void":
        return 0
    return count + 1


def definitions(path):
    """(line, body lines, signature) of each function defined at namespace scope in `path`."""
    lines = path.read_text(errors="replace").splitlines()
    depth, start, signature = 0, None, ""
    for number, line in enumerate(lines):
        code = NOISE.sub("", line)
        if re.match(r"^(namespace\b.*\{|\}\s*// namespace)", line):
            signature = ""
            continue
        if depth == 0 and start is None:
            signature += " " + code
            if "{" in code:
                head = signature[: signature.index("{")]
                is_type = re.match(r"^\s*(template\s*<.*>\s*)?(struct|class|enum|union)\b", head)
                if "(" in head and not is_type and not re.search(r"=\s*$", head.strip()):
                    start = number
                    signature = head
        depth += code.count("{") - code.count("}")
        if depth == 0:
            if start is not None:
                yield start + 1, number - start, signature
                start = None
            if code.rstrip().endswith((";", "}")):
                signature = ""


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-lines", type=int, default=60)
    parser.add_argument("--max-parameters", type=int, default=6)
    parser.add_argument("root", nargs="?", default=pathlib.Path(__file__).resolve().parent.parent)
    args = parser.parse_args()
    root = pathlib.Path(args.root)
    problems = []
    for layer in LAYERS:
        for path in sorted((root / layer).rglob("*.cc")):
            if path.name.endswith("_test.cc"):
                continue
            for line, length, signature in definitions(path):
                where = f"{path.relative_to(root)}:{line}"
                if length > args.max_lines:
                    problems.append(f"{where}: body of {length} lines (at most {args.max_lines})")
                count = parameter_count(signature)
                if count > args.max_parameters:
                    problems.append(
                        f"{where}: {count} parameters (at most {args.max_parameters})")
    for problem in problems:
        print("functions: " + problem)
    if problems:
        return 1
    print(f"functions: ok (bodies of at most {args.max_lines} lines, at most "
          f"{args.max_parameters} parameters)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
