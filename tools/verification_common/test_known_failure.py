#!/usr/bin/python3
"""Self-test of known_failure.py: the wrapper passes a known failure that fails as recorded and
fails every other outcome (a pass, another failed assertion, an expected failure that now passes,
a crash, a run that never reaches its assertions). Registered in ctest (label `unit`)."""
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
WRAPPER = HERE / "known_failure.py"

KNOWN = """# comment: measured numbers
fails: A holds
fails full: B holds
"""


def fake_run(lines, code):
    """A shell command that prints a case's output and exits with code."""
    text = "\n".join(lines).replace("'", "'\\''")
    return ["sh", "-c", f"printf '%s\\n' '{text}'; exit {code}"]


def assertions(a_ok, b_ok, c_ok=True):
    checks = [("A holds", a_ok), ("B holds", b_ok), ("C holds", c_ok)]
    out = ["Assertions:"] + [f"  [{'PASS' if ok else 'FAIL'}] {d}: measured" for d, ok in checks]
    failed = [d for d, ok in checks if not ok]
    out.append("RESULT: PASS" if not failed else "RESULT: FAIL failed: " + "; ".join(failed))
    return out, (0 if not failed else 1)


def wrapper(case_dir, variant, cmd):
    p = subprocess.run([sys.executable, str(WRAPPER), "--case-dir", str(case_dir), "--variant", variant, "--"]
                       + cmd, capture_output=True, text=True)
    return p.returncode, p.stdout


def main():
    bad = []
    with tempfile.TemporaryDirectory() as tmp:
        case = Path(tmp) / "case"
        case.mkdir()
        (case / "KNOWN_FAILURE").write_text(KNOWN)
        cases = [
            # (what, variant, A ok, B ok, C ok, expected wrapper exit)
            ("quick fails as recorded", "quick", False, True, True, 0),
            ("full fails as recorded", "full", False, False, True, 0),
            ("quick: B fails too (not recorded for quick)", "quick", False, False, True, 1),
            ("full: B passes now", "full", False, True, True, 1),
            ("another assertion fails", "quick", False, True, False, 1),
            ("the case passes", "quick", True, True, True, 1),
        ]
        for what, variant, a, b, c, want in cases:
            lines, code = assertions(a, b, c)
            got, out = wrapper(case, variant, fake_run(lines, code))
            if got != want:
                bad.append(f"{what}: wrapper exit {got}, expected {want}\n{out}")
        for what, cmd in [("crash (exit 2)", fake_run(["RESULT: ERROR (a run did not complete)"], 2)),
                          ("traceback, exit 1, no RESULT", fake_run(["Traceback: boom"], 1)),
                          ("exit 1 without assertions", fake_run(["RESULT: FAIL (a run did not complete)"], 1))]:
            got, out = wrapper(case, "quick", cmd)
            if got != 1:
                bad.append(f"{what}: wrapper exit {got}, expected 1\n{out}")
    for b in bad:
        print("FAIL:", b)
    print(f"{'FAIL' if bad else 'PASS'}: {len(bad)} wrong outcome(s) of known_failure.py")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
