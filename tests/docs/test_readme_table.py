#!/usr/bin/python3
"""The README's verification table is checked against the cases (issues 33 and 37).

    test_readme_table.py CAIRN_BINARY SOURCE_DIR

Every verification/<case>/ with a `run` script has a row in README.md's table, every row names
a case that exists, a row says "known failure" exactly when the case has a KNOWN_FAILURE file,
and every decimal number a row quotes (2.04, 131.0, 0.24 ...) appears in that case's own
README.md, whose numbers come from the case's runs. Exit 0 when all hold; prints each failure.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

ROW = re.compile(r"^\| `([a-z0-9_]+)` \|(.*)$")
DECIMAL = re.compile(r"(?<![\w.])\d+\.\d+(?![\w.])")


def main() -> int:
    source = Path(sys.argv[2]) if len(sys.argv) > 2 else Path(__file__).resolve().parents[2]
    readme = (source / "README.md").read_text()
    rows = {}
    for line in readme.splitlines():
        m = ROW.match(line)
        if m:
            rows[m.group(1)] = m.group(2)
    cases = sorted(p.name for p in (source / "verification").iterdir() if (p / "run").exists())
    failures = []
    for case in cases:
        if case not in rows:
            failures.append(f"verification/{case} has no row in README.md's verification table")
    for case, text in rows.items():
        folder = source / "verification" / case
        if not (folder / "run").exists():
            failures.append(f"README.md's row `{case}` names no verification case")
            continue
        known = (folder / "KNOWN_FAILURE").exists()
        says_known = "known failure" in text.lower()
        if known != says_known:
            failures.append(f"README.md's row `{case}`: {'says' if says_known else 'does not say'} "
                            f"'known failure', but the case {'has' if known else 'has no'} KNOWN_FAILURE")
        case_readme = (folder / "README.md").read_text() if (folder / "README.md").exists() else ""
        shows = [cell for cell in text.split("|") if cell.strip()][-1]  # the "what it shows" column
        for number in DECIMAL.findall(shows):
            if number not in case_readme:
                failures.append(f"README.md's row `{case}` quotes {number}, which verification/{case}/README.md "
                                "does not state")
    for f in failures:
        print("FAIL:", f)
    print(f"{len(rows)} rows, {len(cases)} cases: {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
