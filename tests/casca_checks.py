"""The tests' record of checks: a PASS/FAIL line for each (its figure, the bound and the
independent answer) and the "N passed, M failed" summary, with a non-zero exit status if
anything failed. Standard library only, so that a test without numpy (test_docs) has it too."""
import sys


class Checks:
    def __init__(self):
        self.passed = 0
        self.failed = 0

    def record(self, name, ok, detail=""):
        if ok:
            self.passed += 1
        else:
            self.failed += 1
        print(("PASS " if ok else "FAIL ") + name + (": " + detail if detail else ""), flush=True)

    def le(self, name, value, bound):
        self.record(name, value <= bound, "%.6g <= %.6g" % (value, bound))

    def close(self, name, value, expected, rtol):
        self.record(name, abs(value - expected) <= rtol * abs(expected),
                    "%.6g vs %.6g (rtol %.3g, off by %.3g%%)"
                    % (value, expected, rtol, 100 * abs(value - expected) / abs(expected)))

    def finish(self):
        print("%d passed, %d failed" % (self.passed, self.failed))
        sys.exit(1 if self.failed else 0)
