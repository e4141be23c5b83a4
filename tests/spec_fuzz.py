"""Hypothesis strategies shared by the spec-parser tests."""

from __future__ import annotations

from hypothesis import strategies as st


@st.composite
def token_mutations(draw, sources, garbage):
    """A text drawn from ``sources`` after one to four token-level mutations: a token deleted,
    duplicated or replaced by one drawn from ``garbage``, two lines swapped, a line repeated."""
    lines = [line.split() for line in draw(sources).splitlines()]
    for _ in range(draw(st.integers(1, 4))):
        row = draw(st.integers(0, len(lines) - 1))
        kind = draw(st.sampled_from(["delete", "duplicate", "replace", "swap", "dup_line"]))
        tokens = lines[row]
        if kind == "swap":
            other = draw(st.integers(0, len(lines) - 1))
            lines[row], lines[other] = lines[other], lines[row]
        elif kind == "dup_line":
            lines.insert(row, list(tokens))
        elif tokens:
            column = draw(st.integers(0, len(tokens) - 1))
            if kind == "delete":
                del tokens[column]
            elif kind == "duplicate":
                tokens.insert(column, tokens[column])
            else:
                tokens[column] = draw(garbage)
    return "\n".join(" ".join(tokens) for tokens in lines)
