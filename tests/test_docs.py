"""docs/deck.md against the deck reader's sources: every key documented, no key invented, the
types and the literal defaults as the code has them.

Reads SOURCE_DIR/src/input/deck_lint.f90 (the key table keys(*): every (group, key, type) the
reader accepts; vec3(*): the keys that are vectors of three; str_lists(*): the string keys
that take a list), SOURCE_DIR/src/input/deck.f90 (the cfg types' `:: name = value`
declarations and the read_* routines) and SOURCE_DIR/docs/deck.md, whose sections start at a
`## &group` heading and whose key rows are table rows `| `key` | type | default | meaning |`.
Asserts:
- parsing: keys(*) gives at least 50 keys in the 7 groups run, output, body, restraint,
  load, obstacle, contact, and vec3(*) and str_lists(*) are found; docs/deck.md has a
  `## &group` section for each of the 7 groups, in that order (deck order), and no other;
- (a) every (group, key) of keys(*) has a key row in its group's section of docs/deck.md;
- (b) every key row of docs/deck.md names a key that keys(*) lists for that section's group
  (no documented key the reader refuses), and no key has two rows in one section;
- the type cell of each key row agrees with keys(*): a real key's cell contains "real" (a
  vec3 key's starts with "3 reals"), an integer's "integer", a logical's "logical", a
  string's "string" (a str_lists key's "strings");
- (c) for every documented real, integer or logical key whose default in deck.f90 is a
  literal (a number, .true./.false., or [n, n, n]) in its group's cfg type (run_cfg_t for
  &run, ...), the first `code` span of the row's default cell is that value (numbers equal
  within 1e-12 relative; a scalar source default of a vec3 key is each of the 3 documented
  numbers). Skipped, and listed in the output: keys whose declared default is computed or
  absent (`unset`, `-huge(...)`, `huge(...)`, no initialiser: the documented default is then
  a rule such as "t_end/100" or "required"), and keys whose read routine sets the namelist
  variable to `unset` before the read and does not fall back to the type's value when it
  stays unset (&output track: the type's 0 is not its default); string defaults are not
  compared.

usage: test_docs.py SOURCE_DIR
(Python 3, standard library only.)
"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from casca_checks import Checks  # noqa: E402

GROUPS = ["run", "output", "body", "restraint", "load", "obstacle", "contact"]
ROUTINE = {"run": "read_run", "output": "read_output", "body": "read_bodies",
           "restraint": "read_restraints", "load": "read_loads", "obstacle": "read_obstacles",
           "contact": "read_contact"}


def strip_comments(text):
    """Fortran source without its ! comments (none of these files has a ! inside a string
    on a line that matters here)."""
    return "\n".join(line.split("!", 1)[0] for line in text.splitlines())


def name_list(src, name):
    """The quoted names of the character parameter array `name(*) = [ ... ]`."""
    m = re.search(r"\b%s\(\*\)\s*=\s*\[(.*?)\]" % name, src, re.S)
    return set(re.findall(r"'(\w+)'", m.group(1))) if m else set()


def split_top(s):
    """s split at the commas outside brackets, parentheses and quotes."""
    parts, depth, quote, cur = [], 0, None, ""
    for ch in s:
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch in "([":
            depth += 1
        elif ch in ")]":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        cur += ch
    parts.append(cur)
    return [p.strip() for p in parts if p.strip()]


NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eEdD][+-]?\d+)?(_dp)?$")


def literal(s):
    """A Fortran literal (number, logical, [a, b, c] of them) as float/bool/list; else None."""
    s = s.strip()
    if s.lower() in (".true.", ".false."):
        return s.lower() == ".true."
    if s.startswith("[") and s.endswith("]"):
        items = [literal(x) for x in split_top(s[1:-1])]
        return None if not items or any(x is None for x in items) else items
    m = NUMBER.match(s)
    if m:
        return float(s.replace("_dp", "").lower().replace("d", "e"))
    return None


def type_defaults(src, group):
    """{name: declared default text or None} of the group's cfg type in deck.f90."""
    m = re.search(r"^\s*type\s*::\s*%s_cfg_t\s*$(.*?)^\s*end type" % group, src, re.M | re.S)
    out = {}
    if not m:
        return out
    for line in m.group(1).splitlines():
        if "::" not in line:
            continue
        for decl in split_top(line.split("::", 1)[1]):
            name = re.match(r"(\w+)", decl).group(1).lower()
            out[name] = decl.split("=", 1)[1].strip() if "=" in decl else None
    return out


def reader_unset(src, group):
    """Names the group's read routine sets to unset before the read and does not fall back
    from (`if (x /= unset) c%x = x`)."""
    m = re.search(r"subroutine %s\b(.*?)end subroutine %s\b" % (ROUTINE[group], ROUTINE[group]), src, re.S)
    if not m:
        return set()
    body = m.group(1)
    set_unset = set(re.findall(r"(?<![\w%])(\w+)\s*=\s*unset\b", body))
    kept = set(re.findall(r"if\s*\(\s*(\w+)\s*/=\s*unset\s*\)\s*c%\1\s*=\s*\1\b", body))
    return set_unset - kept


def cells(row):
    """The cells of a markdown table row (\\| inside a cell is not a separator)."""
    parts = re.split(r"(?<!\\)\|", row.strip())
    return [c.strip() for c in parts[1:-1]]


source = os.path.abspath(sys.argv[1])
ck = Checks()
lint = strip_comments(open(os.path.join(source, "src", "input", "deck_lint.f90")).read())
deck_src = strip_comments(open(os.path.join(source, "src", "input", "deck.f90")).read())
doc = open(os.path.join(source, "docs", "deck.md")).read()

# the key table
keys = {}   # (group, key) -> type letter
for g, k, t in re.findall(r"key_t\(\s*'(\w+)'\s*,\s*'(\w+)'\s*,\s*'(\w)'\s*\)", lint):
    keys[(g, k)] = t
vec3, lists = name_list(lint, "vec3"), name_list(lint, "str_lists")
ck.record("deck_lint.f90 keys(*): at least 50 keys, in the 7 groups",
          len(keys) >= 50 and {g for g, _ in keys} == set(GROUPS),
          "%d keys, groups %s" % (len(keys), sorted({g for g, _ in keys})))
ck.record("deck_lint.f90 vec3(*) and str_lists(*) found", len(vec3) >= 5 and len(lists) >= 2,
          "vec3 %s, str_lists %s" % (sorted(vec3), sorted(lists)))

# the documented rows, by section
heads = [(m.start(), m.group(1)) for m in re.finditer(r"^## &(\w+)", doc, re.M)]
ck.record("docs/deck.md: one `## &group` section per group, in deck order",
          [g for _, g in heads] == GROUPS, "sections %s" % [g for _, g in heads])
rows = {}   # group -> list of (key, cells)
for i, (at, g) in enumerate(heads):
    end = re.compile(r"^## ", re.M).search(doc, at + 3)
    text = doc[at:end.start() if end else len(doc)]
    for line in text.splitlines():
        m = re.match(r"^\|\s*`(\w+)`\s*\|", line)
        if m:
            rows.setdefault(g, []).append((m.group(1), cells(line)))

# (a) every key of keys(*) documented under its group
for g in GROUPS:
    documented = {k for k, _ in rows.get(g, [])}
    missing = sorted(k for gg, k in keys if gg == g and k not in documented)
    n = sum(1 for gg, _ in keys if gg == g)
    ck.record("(a) &%s: each of its %d keys in keys(*) has a row in docs/deck.md's &%s section" % (g, n, g),
              n > 0 and not missing, "missing: %s" % ", ".join(missing) if missing else "")

# (b) no documented key the reader refuses; one row per key
for g, rs in sorted(rows.items()):
    unknown = sorted(k for k, _ in rs if (g, k) not in keys)
    ck.record("(b) &%s: each of the %d key rows of docs/deck.md is a key of &%s in keys(*)" % (g, len(rs), g),
              not unknown, "not in keys(*): %s" % ", ".join(unknown) if unknown else "")
    names = [k for k, _ in rs]
    twice = sorted({k for k in names if names.count(k) > 1})
    ck.record("(b) &%s: no key has two rows" % g, not twice, ", ".join(twice))

# the type cells
WORD = {"r": "real", "i": "integer", "l": "logical", "s": "string"}
bad = []
for g, rs in sorted(rows.items()):
    for k, c in rs:
        t = keys.get((g, k))
        if t is None:
            continue
        cell = c[1] if len(c) > 1 else ""
        ok = WORD[t] in cell
        if t == "r" and k in vec3:
            ok = cell.startswith("3 reals")
        if t == "s" and k in lists:
            ok = "strings" in cell
        if not ok:
            bad.append("&%s %s: '%s' for %s%s" % (g, k, cell, WORD[t], " (vector of 3)" if k in vec3 else
                                                  " (list)" if k in lists else ""))
ck.record("type cells agree with keys(*) (and vec3(*), str_lists(*))", not bad and len(rows) > 0,
          "; ".join(bad))

# (c) literal defaults
skipped = []
compared = 0
for g in GROUPS:
    decl = type_defaults(deck_src, g)
    ck.record("deck.f90: %s_cfg_t found with initialised components" % g,
              any(v is not None for v in decl.values()), "%d components" % len(decl))
    overridden = reader_unset(deck_src, g)
    for k, c in rows.get(g, []):
        t = keys.get((g, k))
        if t not in ("r", "i", "l"):
            continue
        text = decl.get(k)
        src = literal(text) if text is not None else None
        if src is None or k in overridden:
            skipped.append("&%s %s (%s)" % (g, k, "read as unset" if k in overridden else text or "no initialiser"))
            continue
        compared += 1
        span = re.search(r"`([^`]*)`", c[2] if len(c) > 2 else "")
        doc_val = None
        if span:
            items = [literal(x) for x in span.group(1).split(",")]
            if items and all(x is not None for x in items):
                doc_val = items[0] if len(items) == 1 else items
        want = src
        if k in vec3 and not isinstance(src, list):
            want = [src] * 3

        def same(a, b):
            if isinstance(a, list) or isinstance(b, list):
                return isinstance(a, list) and isinstance(b, list) and len(a) == len(b) and \
                    all(same(x, y) for x, y in zip(a, b))
            if isinstance(a, bool) or isinstance(b, bool):
                return isinstance(a, bool) and isinstance(b, bool) and a == b
            return abs(a - b) <= 1e-12 * max(1.0, abs(b))

        ck.record("(c) &%s %s: documented default equals deck.f90's" % (g, k),
                  doc_val is not None and same(doc_val, want),
                  "docs/deck.md '%s', deck.f90 '%s'" % (span.group(1) if span else (c[2] if len(c) > 2 else ""),
                                                         text))
ck.record("(c) at least 30 literal defaults compared", compared >= 30, "%d compared" % compared)
print("(c) skipped (default computed or absent in deck.f90): " + "; ".join(skipped))
ck.finish()
