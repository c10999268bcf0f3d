#!/usr/bin/python3
"""Runs a known-failure verification case and passes only when it fails exactly as recorded.

    known_failure.py --case-dir verification/<case> --variant quick|full -- <case run command...>

A case's run script follows the exit-code convention of cairn_case.finish: 0 when every assertion
holds, 1 when its assertions were evaluated and at least one failed (the "Assertions:" block, then
"RESULT: FAIL failed: ..."); anything else (a traceback, a cairn run that did not complete, a
missing binary) is a crash. The case's KNOWN_FAILURE file names the assertions that are expected
to fail, one per line, by the start of their description as the run prints it after "[FAIL] ":

    fails: <description>          expected to fail in both variants
    fails quick: <description>    only in the quick variant
    fails full: <description>     only in the full variant

(lines starting with # are comments: what fails, the measured numbers, the README section; a line
`expensive-quick` tells verification/CMakeLists.txt to keep the quick check out of the default
suite).

This wrapper exits 0 only when the run exits 1 with a RESULT: FAIL line and the failed assertions
are exactly the expected ones. It exits 1, saying why, when the case passes (a known failure that
now reproduces: remove KNOWN_FAILURE and update the README), when an expected failure now passes,
when another assertion fails, or when the run crashes or never reaches its assertions.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path


def expected_failures(known_failure: Path, variant: str) -> list[str]:
    out = []
    for raw in known_failure.read_text().splitlines():
        line = raw.strip()
        if not line or line.startswith("#") or line == "expensive-quick":
            continue
        head, sep, text = line.partition(":")
        words = head.split()
        if not sep or not words or words[0] != "fails" or len(words) > 2 or \
                (len(words) == 2 and words[1] not in ("quick", "full")):
            raise SystemExit(f"{known_failure}: cannot read the line {raw!r} "
                             "(expected 'fails: ...', 'fails quick: ...' or 'fails full: ...')")
        if len(words) == 1 or words[1] == variant:
            out.append(text.strip())
    return out


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--case-dir", required=True, type=Path)
    p.add_argument("--variant", required=True, choices=["quick", "full"])
    p.add_argument("command", nargs=argparse.REMAINDER, help="-- then the case's run command")
    a = p.parse_args()
    cmd = a.command[1:] if a.command[:1] == ["--"] else a.command
    if not cmd:
        p.error("no run command after --")
    expected = expected_failures(a.case_dir / "KNOWN_FAILURE", a.variant)
    if not expected:
        print(f"KNOWN_FAILURE of {a.case_dir.name} names no assertion for the {a.variant} variant")
        return 1

    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    sys.stdout.write(proc.stdout)
    lines = proc.stdout.splitlines()
    result = [ln for ln in lines if ln.startswith("RESULT:")]
    failed = [ln.split("[FAIL] ", 1)[1] for ln in lines if ln.lstrip().startswith("[FAIL] ")]
    passed = [ln.split("[PASS] ", 1)[1] for ln in lines if ln.lstrip().startswith("[PASS] ")]
    name = a.case_dir.name

    print("\nknown-failure check:")
    if proc.returncode == 0:
        print(f"  {name} PASSES now: the known failure reproduces the paper. Remove KNOWN_FAILURE, update "
              "its README and the top README's table.")
        return 1
    if proc.returncode != 1 or not result or not result[-1].startswith("RESULT: FAIL failed:"):
        print(f"  {name} CRASHED or did not reach its assertions (exit {proc.returncode}, last RESULT line: "
              f"{result[-1] if result else 'none'}); a known failure must fail its assertion cleanly.")
        return 1
    problems = []
    for e in expected:
        if not any(f.startswith(e) for f in failed):
            now = [q for q in passed if q.startswith(e)]
            problems.append(f"expected to fail but {'passes now' if now else 'was not evaluated'}: {e}"
                            + (f" -> {now[0]}" if now else ""))
    for f in failed:
        if not any(f.startswith(e) for e in expected):
            problems.append(f"fails but is not a recorded known failure: {f}")
    if problems:
        print(f"  {name} no longer fails as recorded in KNOWN_FAILURE:")
        for prob in problems:
            print(f"    {prob}")
        return 1
    print(f"  {name} fails as recorded ({len(failed)} expected failure(s)); KNOWN_FAILURE holds.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
