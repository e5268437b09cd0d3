"""The command line's tables: one number format, and a layout that never cuts a cell.

Every rich table ``flexsat`` prints goes through :func:`print_table`. Cells are
formatted by :func:`cell` (numbers by :func:`format_number`: four significant
digits, an exponent when the magnitude asks for one), and the columns are laid out
here rather than by rich's own shrinking, which cuts a cell with an ellipsis when
the terminal is narrow: a column of values is never narrower than its longest word
(a number is one word), text wraps at spaces, and a table that does not fit even so
is printed in several parts, each repeating the first column.

A requirement's verdict that was not judged (a run that ends before its observation
window: ``r1_pass`` None, a pass rate over no judged case) reads "not judged" in the
rows :data:`VERDICT_ROW` names, never "FAIL" nor a bare "-".
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence

from rich.console import Console
from rich.table import Table

__all__ = ["NOT_JUDGED", "SIGNIFICANT_DIGITS", "VERDICT_ROW", "cell", "format_number",
           "print_table"]  # fmt: skip

SIGNIFICANT_DIGITS = 4
"""Significant digits of every number in a table."""

NOT_JUDGED = "not judged"
"""The text of a verdict that was not judged (None, or a pass rate of NaN)."""

VERDICT_ROW = re.compile(r"r\d_pass(_rate)?|R\d pass rate\b.*")
"""Labels (first cell) of the rows that hold a requirement's verdict or pass rate: a
missing value there (None, NaN) is :data:`NOT_JUDGED`."""

_LABEL_MIN = 12  # narrowest first (label) column, its words folded below it


def format_number(value: float | int, digits: int = SIGNIFICANT_DIGITS) -> str:
    """A number as a table shows it: ``digits`` significant digits, an exponent if needed.

    Parameters
    ----------
    value : float or int
        The number, in whatever unit its column names [any]; integers are printed whole.
    digits : int
        Significant digits of a float.

    Returns
    -------
    str
        ``"5.065e-07"``, ``"0.3507"``, ``"1.235e+04"``, ``"20"``, ``"nan"``, ``"inf"``.
    """
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, int):
        return str(value)
    value = float(value)
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return f"{value:.{digits}g}"


def cell(value: object) -> str:
    """The text of one table cell: numbers by :func:`format_number`, lists and dicts flat.

    Parameters
    ----------
    value : object
        A number, bool, string, None, list (nested lists are rows in brackets) or dict.

    Returns
    -------
    str
        The cell's text; its words are separated by spaces, so it wraps between them.
    """
    if value is None:
        return "-"
    if isinstance(value, bool | str):
        return str(value)
    if isinstance(value, int | float):
        return format_number(value)
    if isinstance(value, Mapping):
        return ", ".join(f"{k}: {cell(v)}" for k, v in value.items()) if value else "-"
    if isinstance(value, Sequence):
        if not value:
            return "-"
        if all(isinstance(v, Sequence) and not isinstance(v, str) for v in value):
            return " ".join(f"[{cell(v)}]" for v in value)
        return ", ".join(cell(v) for v in value)
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return cell(value.tolist())
    return str(value)


def print_table(
    console: Console,
    title: str,
    header: Sequence[str],
    rows: Sequence[Sequence[object]],
    *,
    right: Sequence[bool] | None = None,
) -> None:
    """Print a table whose cells are never cut, whatever the terminal's width.

    Parameters
    ----------
    console : rich.console.Console
        Where it is printed (its width is the terminal's, or ``COLUMNS``).
    title : str
        The table's title.
    header : sequence of str
        Column names; the first column labels the rows and is repeated in every part.
    rows : sequence of sequence
        The cells, one sequence per row; non-strings are formatted by :func:`cell`,
        except a missing value (None, NaN) in a row whose label matches
        :data:`VERDICT_ROW`, which reads :data:`NOT_JUDGED`.
    right : sequence of bool, optional
        Right-align that column (default: every column but the first).
    """
    texts = [[c if isinstance(c, str) else _verdict_cell(c) if k and _verdict_row(row) else cell(c)
              for k, c in enumerate(row)] for row in rows]  # fmt: skip
    n = len(header)
    right = [k > 0 for k in range(n)] if right is None else list(right)
    natural = [_width(header[k], [row[k] for row in texts]) for k in range(n)]
    least = [max((_longest_word(row[k]) for row in texts), default=1) for k in range(n)]
    least[0] = min(natural[0], _LABEL_MIN)  # the label column folds its long words
    available = max(console.width, 20)
    for index, part in enumerate(_parts(natural, least, available)):
        widths = _fit([natural[k] for k in part], [least[k] for k in part], available)
        table = Table(title=title if index == 0 else f"{title} (continued)")
        for k, width in zip(part, widths, strict=True):
            table.add_column(header[k], width=width, overflow="fold",
                             justify="right" if right[k] else "left")  # fmt: skip
        for row in texts:
            table.add_row(*(row[k] for k in part))
        console.print(table)


def _verdict_row(row: Sequence[object]) -> bool:
    return bool(row) and isinstance(row[0], str) and VERDICT_ROW.fullmatch(row[0]) is not None


def _verdict_cell(value: object) -> str:
    """A verdict's cell: :data:`NOT_JUDGED` for a missing value, else :func:`cell`."""
    missing = value is None or (isinstance(value, float) and math.isnan(value))
    return NOT_JUDGED if missing else cell(value)


def _width(head: str, cells: list[str]) -> int:
    lines = [line for text in (head, *cells) for line in text.splitlines() or [""]]
    return max(1, *(len(line) for line in lines))


def _longest_word(text: str) -> int:
    return max((len(word) for word in text.split()), default=1)


def _frame(n_columns: int) -> int:
    """Characters a table of n columns spends outside its cells: padding and borders."""
    return 3 * n_columns + 1


def _parts(natural: list[int], least: list[int], available: int) -> list[list[int]]:
    """Groups of column indices, each starting with column 0, each fitting ``available``."""
    parts: list[list[int]] = []
    current = [0]
    for k in range(1, len(natural)):
        if sum(least[j] for j in (*current, k)) + _frame(len(current) + 1) > available and (
            len(current) > 1
        ):
            parts.append(current)
            current = [0]
        current.append(k)
    parts.append(current)
    return parts


def _fit(natural: list[int], least: list[int], available: int) -> list[int]:
    """Column widths: natural ones, the roomiest narrowed first until the table fits."""
    widths = list(natural)
    room = available - _frame(len(widths))
    while sum(widths) > room:
        slack = [w - m for w, m in zip(widths, least, strict=True)]
        k = max(range(len(widths)), key=slack.__getitem__)
        if slack[k] <= 0:
            break  # a single value column wider than the terminal: its words stay whole
        widths[k] -= 1
    return widths
