"""Line layout of printed code: statements longer than the line width broken inside brackets.

The printers write one statement per line, however long its expression. Python allows a line
break wherever a bracket is open, so a long statement is laid out by wrapping its right-hand
side (or an ``if`` condition) in parentheses where it is not bracketed already, and breaking it
greedily at the spaces between tokens inside brackets: each line as full as the width allows,
continuation lines indented one step deeper. Comments are refilled at spaces. Only the layout
changes: the statement parses to the same tree (a test checks this on every bundled arm).
"""

from __future__ import annotations

import io
import tokenize
from itertools import pairwise

WIDTH = 100
INDENT = "    "


def wrap_code(code: str, width: int = WIDTH) -> str:
    """Every line of code longer than width laid out over several lines (see the module).

    Only lines that hold a whole statement or a comment are touched: never a line inside a
    string or a statement that already spans several lines.
    """
    whole = _single_lines(code)
    out: list[str] = []
    for row, line in enumerate(code.split("\n"), start=1):
        out += wrap_line(line, width) if len(line) > width and row in whole else [line]
    return "\n".join(out)


def _single_lines(code: str) -> set[int]:
    """The rows (1-based) of code holding a whole logical line or only a comment."""
    rows: set[int] = set()
    first = None
    try:
        for tok in tokenize.generate_tokens(io.StringIO(code).readline):
            if tok.type == tokenize.COMMENT and first is None:
                rows.add(tok.start[0])
            elif tok.type == tokenize.NEWLINE:
                if first is not None and first == tok.start[0]:
                    rows.add(first)
                first = None
            elif tok.type not in (tokenize.NL, tokenize.INDENT, tokenize.DEDENT) and first is None:
                first = tok.start[0]
    except (tokenize.TokenError, SyntaxError):
        return set()
    return rows


def wrap_line(line: str, width: int = WIDTH) -> list[str]:
    """One line laid out within width where it can be: a comment refilled, a statement broken
    inside brackets; a line that is neither is returned as it is."""
    body = line.lstrip(" ")
    indent = line[: len(line) - len(body)]
    if body.startswith("#"):
        return _refill_comment(indent, body[1:].strip(), width)
    tokens = _tokens(body, comments=True)
    comments = [t for t in tokens or () if t.type == tokenize.COMMENT]
    if comments:  # a trailing comment goes on a line of its own, above the statement
        code = body[: comments[0].start[1]].rstrip()
        above = _refill_comment(indent, comments[0].string[1:].strip(), width)
        return above + wrap_line(indent + code, width)
    text = _bracketed(body)
    if text is None:
        return [line]
    breaks = _break_points(text)
    lines: list[str] = []
    start = 0
    prefix = indent
    while len(prefix) + len(text) - start > width:
        fits = [b for b in breaks if start < b and len(prefix) + b - start <= width]
        if not fits:
            break
        cut = fits[-1]
        lines.append(prefix + text[start:cut])
        start = cut + 1  # the space at the break goes
        prefix = indent + INDENT
    lines.append(prefix + text[start:])
    return lines


def _refill_comment(indent: str, words: str, width: int) -> list[str]:
    lines: list[str] = []
    current = ""
    for word in words.split(" "):
        if current and len(indent) + 2 + len(current) + 1 + len(word) > width:
            lines.append(f"{indent}# {current}")
            current = word
        else:
            current = f"{current} {word}" if current else word
    lines.append(f"{indent}# {current}")
    return lines


def _bracketed(body: str) -> str | None:
    """The statement with its expression in brackets: `x = (...)`, `if (...):`, `return (...)`;
    None if it does not tokenize as one logical line."""
    tokens = _tokens(body)
    if tokens is None:
        return None
    depth = 0
    for tok in tokens:
        if tok.type == tokenize.OP and tok.string in "([{":
            depth += 1
        elif tok.type == tokenize.OP and tok.string in ")]}":
            depth -= 1
        elif depth == 0 and tok.type == tokenize.OP and tok.string == "=":
            head, rest = body[: tok.end[1]], body[tok.end[1] :].strip()
            return f"{head} {_parenthesized(rest)}"
    if body.startswith("if ") and body.endswith(":"):
        return f"if {_parenthesized(body[3:-1].strip())}:"
    if body.startswith("return "):
        return f"return {_parenthesized(body[7:].strip())}"
    return body


def _parenthesized(expr: str) -> str:
    """expr in parentheses, unless one bracket pair already encloses all of it."""
    tokens = _tokens(expr)
    if tokens and tokens[0].string in "([" and _closing(tokens) == len(tokens) - 1:
        return expr
    return f"({expr})"


def _closing(tokens: list[tokenize.TokenInfo]) -> int:
    """The index of the token closing the bracket opened by tokens[0]."""
    depth = 0
    for k, tok in enumerate(tokens):
        if tok.type == tokenize.OP and tok.string in "([{":
            depth += 1
        elif tok.type == tokenize.OP and tok.string in ")]}":
            depth -= 1
            if depth == 0:
                return k
    return -1


def _tokens(text: str, comments: bool = False) -> list[tokenize.TokenInfo] | None:
    """The tokens of one line of code (no newlines or end marker, and no comments unless
    asked), or None if the line is not a whole logical line."""
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except (tokenize.TokenError, SyntaxError):
        return None
    skip = {tokenize.NEWLINE, tokenize.NL, tokenize.ENDMARKER}
    if not comments:
        skip.add(tokenize.COMMENT)
    kept = [t for t in tokens if t.type not in skip]
    if any(t.start[0] != 1 for t in kept) or any(t.type == tokenize.INDENT for t in kept):
        return None
    return kept


def _break_points(text: str) -> list[int]:
    """Offsets of the spaces between tokens inside brackets, where a line may break."""
    tokens = _tokens(text)
    if tokens is None:
        return []
    points = []
    depth = 0
    for before, after in pairwise(tokens):
        if before.type == tokenize.OP and before.string in "([{":
            depth += 1
        elif before.type == tokenize.OP and before.string in ")]}":
            depth -= 1
        gap = text[before.end[1] : after.start[1]]
        if depth > 0 and gap == " " and after.string not in ")]},:":
            points.append(before.end[1])
    return points


def wrap_c(code: str, width: int = WIDTH) -> str:
    """Every line of generated C longer than width broken greedily at its spaces, each
    continuation indented two steps deeper than the line (C does not care where a line
    breaks between tokens, nor inside a comment). Preprocessor lines and lines holding a
    string literal are left whole (the generated C has none that long)."""
    out: list[str] = []
    for line in code.split("\n"):
        if len(line) <= width or line.lstrip().startswith("#") or '"' in line:
            out.append(line)
            continue
        indent = line[: len(line) - len(line.lstrip())] + 2 * INDENT
        rest, first = line, True
        while len(rest) > width:
            cut = rest.rfind(" ", len(indent) + 1 if not first else len(indent) // 2, width + 1)
            if cut <= len(rest) - len(rest.lstrip()):
                break  # one token longer than the line: left as it is
            out.append(rest[:cut].rstrip())
            rest, first = indent + rest[cut + 1 :].lstrip(), False
        out.append(rest)
    return "\n".join(out)
