#!/usr/bin/env python3
"""Fails when a function in the given C++ files is longer than --max lines.

The commands in driver/cli only wire (docs/pages/architecture/cli.md): this keeps them so.
A function runs from the first line of its signature to its closing brace; lambdas and
local blocks count toward the function around them. Comments, strings and preprocessor
lines are blanked first, so braces inside them do not count.

  function_length.py --max 100 FILE...     check
  function_length.py --selftest            a long function must be found, a short one not
"""
import re
import sys


def blank(text):
    """The source with comments, string and character literals and # lines blanked."""
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
        elif text.startswith('R"', i) and (m := re.match(r'R"([^(\s]*)\(', text[i:])):
            close = ")" + m.group(1) + '"'
            j = text.find(close, i)
            j = n if j < 0 else j + len(close)
        elif text[i] == '"' or (text[i] == "'" and not (i > 0 and text[i - 1].isalnum())):
            q, j = text[i], i + 1
            while j < n and text[j] != q and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
        elif text[i] == "#" and (i == 0 or text[i - 1] == "\n"):
            j = text.find("\n", i)
            while j > 0 and text[j - 1] == "\\":
                j = text.find("\n", j + 1)
            j = n if j < 0 else j
        else:
            out.append(text[i])
            i += 1
            continue
        out.append(re.sub(r"[^\n]", " ", text[i:j]))
        i = j
    return "".join(out)


def functions(text):
    """(first line, last line, name) of every function body at namespace or class level."""
    src = blank(text)
    found, stack, head = [], [], 0  # stack: "fn" or "scope" per open brace
    for i, c in enumerate(src):
        if c == "{":
            if "fn" in stack:
                stack.append("inner")
                continue
            before = src[head:i]
            sig = re.sub(r"(\s*\b(const|override|noexcept|final|mutable)\b)+\s*$", "", before.rstrip())
            sig = re.sub(r"\s*->\s*[\w:<>,\s*&]+$", "", sig)
            if sig.endswith(")") and not re.match(r"\s*(namespace|struct|class|enum|union)\b", before):
                start = head + (len(before) - len(before.lstrip()))
                name = re.search(r"([\w:~]+)\s*\(", before)
                stack.append(("fn", src.count("\n", 0, start) + 1, name.group(1) if name else "?"))
            else:
                stack.append("scope")
            head = i + 1
        elif c == "}" and stack:
            top = stack.pop()
            if isinstance(top, tuple):
                found.append((top[1], src.count("\n", 0, i) + 1, top[2]))
            if not any(isinstance(s, tuple) or s == "inner" for s in stack):
                head = i + 1
        elif c == ";" and not any(isinstance(s, tuple) or s == "inner" for s in stack):
            head = i + 1
    return found


def too_long(text, limit):
    return [(a, b, name) for a, b, name in functions(text) if b - a + 1 > limit]


def selftest():
    short = "int f(int a) {\n  return a;\n}\n"
    body = "".join(f'  x += "{{ {k}";  // }}\n' for k in range(120))
    long_fn = "namespace n {\nstruct S { int g() const { return 1; } };\nvoid big(int x) {\n" + body + "  auto l = [&] {\n    x++;\n  };\n}\n}\n"
    ok = not too_long(short, 100)
    found = too_long(long_fn, 100)
    ok = ok and len(found) == 1 and found[0][2] == "big" and found[0][0] == 3 and found[0][1] == 127
    ok = ok and len(functions(long_fn)) == 2  # S::g and big
    print("selftest", "ok" if ok else f"FAILED: {found} {functions(long_fn)}")
    return 0 if ok else 1


def main(argv):
    if argv[1:] == ["--selftest"]:
        return selftest()
    if len(argv) < 4 or argv[1] != "--max":
        print(__doc__)
        return 2
    limit, bad = int(argv[2]), 0
    for path in argv[3:]:
        with open(path, encoding="utf-8") as f:
            for a, b, name in too_long(f.read(), limit):
                print(f"{path}:{a}: {name} is {b - a + 1} lines (at most {limit}): split it into functions")
                bad += 1
    if bad == 0:
        print(f"{len(argv) - 3} file(s): no function longer than {limit} lines")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
