"""Text of the validation scripts: numbers and paths as they print, aligned tables (with column
groups and footer rows), Markdown tables and CSV files of the same rows.
"""

import csv
import math
import os


def show(path):
    """A path as short as it reads: relative to the current folder when inside it."""
    rel = os.path.relpath(path)
    return path if rel.startswith("..") else rel


def num(v):
    """A number for the command line: 0.01 -> '0.01', 20700.0 -> '20700', 1e12 -> '1000000000000'."""
    v = float(v)
    return str(int(v)) if v.is_integer() and abs(v) < 1e16 else repr(v)


def reproduce_command(script, args, drop=("--mixsph", "--doc", "--out")):
    """The command that reproduces a script's table from the source folder: ``script`` (its path
    from there) with ``args``, less the options in ``drop`` and their values (where the
    executable is, where the runs and the table go do not change the numbers)."""
    import shlex
    kept, skip = [], False
    for a in args:
        if skip:
            skip = False
            continue
        if a in drop:
            skip = True
            continue
        if any(a.startswith(d + "=") for d in drop):
            continue
        kept.append(a)
    return "PYTHONPATH=$PWD .venv/bin/python " + shlex.join([script] + kept)


def write_report(lines, script, args, out, name, doc=None):
    """A validation script's report: its Markdown ``lines`` and the command that reproduces them
    (``reproduce_command(script, args)``), printed, written to ``out``/``name`` and, with ``doc``,
    to that page too. Returns the text."""
    text = "\n".join(lines) + "\n\n```sh\n" + reproduce_command(script, args) + "\n```\n"
    print(text)
    os.makedirs(out, exist_ok=True)
    for path in [os.path.join(out, name)] + ([doc] if doc else []):
        with open(path, "w") as fo:
            fo.write(text)
    return text


def fmt(v, spec, na="n/a"):
    """``format(v, spec)`` for a finite number, else ``na``."""
    return format(v, spec) if isinstance(v, (int, float)) and math.isfinite(v) else na


def fmt_duration(s):
    """Seconds as 42s, 3m07s or 1h05m ('--' when not finite)."""
    if not math.isfinite(s):
        return "--"
    s = int(round(s))
    if s < 60:
        return f"{s}s"
    if s < 3600:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s // 3600}h{(s % 3600) // 60:02d}m"


def print_table(columns, rows, footer_rows=()):
    """Print rows of cell strings under ``columns``, (group, header, align) each: align ">" right,
    else left; consecutive columns of one non-empty group get a group heading above theirs,
    groups are parted by " | " (no heading line when no column has a group). A header's trailing
    spaces (to tell apart columns of one name) count for the width and are not shown."""
    width = [max([len(h)] + [len(row[k]) for row in list(rows) + list(footer_rows)])
             for k, (_, h, _) in enumerate(columns)]
    groups = []   # [label, first column, last column]
    for k, (g, _, _) in enumerate(columns):
        if groups and groups[-1][0] == g:
            groups[-1][2] = k
        else:
            groups.append([g, k, k])
    for g, a, b in groups:   # widen a group's last column to fit its label
        span = sum(width[a:b + 1]) + 2 * (b - a)
        if len(g) > span:
            width[b] += len(g) - span

    def line(cells):
        return " | ".join("  ".join(cells[k].rjust(width[k]) if columns[k][2] == ">" else cells[k].ljust(width[k])
                                    for k in range(a, b + 1)) for _, a, b in groups).rstrip()

    text = [line([h.strip() for _, h, _ in columns])]
    if any(g for g, _, _ in groups):
        text.insert(0, " | ".join(g.center(sum(width[a:b + 1]) + 2 * (b - a)) for g, a, b in groups).rstrip())
    rule = "-" * max(len(s) for s in text)
    text += [rule] + [line(r) for r in rows]
    if footer_rows:
        text += [rule] + [line(r) for r in footer_rows]
    print("\n".join(text + [rule]))


def markdown_table(columns, rows):
    """The lines of a Markdown table of rows of cell strings under ``columns`` (as print_table)."""
    lines = ["| " + " | ".join(h.strip() for _, h, _ in columns) + " |",
             "|" + "|".join(" --- " for _ in columns) + "|"]
    return lines + ["| " + " | ".join(c if c else " " for c in row) + " |" for row in rows]


def csv_value(x):
    """A CSV cell: a float with 6 significant digits ('nan' when not finite), anything else as str."""
    if isinstance(x, float):
        return f"{x:.6g}" if math.isfinite(x) else "nan"
    return str(x)


def write_csv(path, fields, rows):
    """A CSV file of the header ``fields`` and the rows (lists of values, written by csv_value)."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(fields)
        for row in rows:
            w.writerow([csv_value(x) for x in row])
