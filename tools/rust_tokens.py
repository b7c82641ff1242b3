"""Rust source read as tokens, for the repository's checks (layers-check,
function-lengths): identifiers, `::` and punctuation with their line;
comments, strings and char literals dropped; `#[cfg(test)]` items cut out.
Enough of Rust's lexical grammar for paths and braces, not a parser."""

import re

IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def tokenize(text: str) -> list[tuple[str, int]]:
    """Rust tokens that matter here (identifiers, `::`, punctuation), with
    their line; comments, strings and char literals dropped."""
    out: list[tuple[str, int]] = []
    i, n, line = 0, len(text), 1
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
        elif c.isspace():
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    line += text[i] == "\n"
                    i += 1
        elif c in "rb" and re.match(r"(br|r)#*\"", text[i:i + 260]):
            m = re.match(r"(br|r)(#*)\"", text[i:])
            end = '"' + m.group(2)
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            line += text.count("\n", i, j)
            i = j
        elif c == '"' or (c == "b" and text.startswith('b"', i)):
            i += 1 if c == '"' else 2
            while i < n and text[i] != '"':
                if text[i] == "\\":
                    i += 1
                line += text[i] == "\n"
                i += 1
            i += 1
        elif c == "'":
            # A char literal ('a', '\n', '\u{..}') or a lifetime ('a).
            m = re.match(r"'(\\.[^']*|[^\\'])'", text[i:i + 12])
            if m:
                i += m.end()
            else:
                i += 1
        elif c == "$" and text.startswith("$crate", i):
            out.append(("crate", line))
            i += 6
        elif c.isalpha() or c == "_":
            m = IDENT.match(text, i)
            out.append((m.group(0), line))
            i = m.end()
        elif text.startswith("::", i):
            out.append(("::", line))
            i += 2
        else:
            out.append((c, line))
            i += 1
    return out


def skip_item(toks, i):
    """Index just past the item starting at `i` (ends at a `;` or a closed
    top-level brace block)."""
    depth = 0
    while i < len(toks):
        t = toks[i][0]
        if t in "([{":
            depth += 1
        elif t in ")]}":
            depth -= 1
            if depth == 0 and t == "}":
                return i + 1
        elif t == ";" and depth == 0:
            return i + 1
        i += 1
    return i


def strip_tests(toks):
    """Tokens without `#[cfg(test)]` items."""
    out, i = [], 0
    while i < len(toks):
        if [t for t, _ in toks[i:i + 7]] == ["#", "[", "cfg", "(", "test", ")", "]"]:
            i = skip_item(toks, i + 7)
            continue
        out.append(toks[i])
        i += 1
    return out
