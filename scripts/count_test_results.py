#!/usr/bin/env python3
"""Counts test cases in gtest/rostest XML result files and prints "N passed, N failed".

Usage: count_test_results.py RESULTS_DIR CTEST_EXIT_CODE CTEST_LOG [CHECKS_FILE]
A test executable that ctest reports as failed but whose XML shows no failing case (it crashed or
timed out before writing its results) counts as one failure. CHECKS_FILE (from scripts/lint) holds
one "<check> passed|failed" line per further check, each counted as one test; given but missing,
unreadable or empty, it counts as one failure. Then each test executable's wall time as ctest
printed it, slowest first, and the skipped cases on the line before the last. The last line is
exactly "N passed, N failed". Exits 1 on any failure or on no tests.
"""
import os
import re
import sys
import xml.etree.ElementTree as ET


def main():
    results_dir, ctest_rc, ctest_log = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    passed = failed = skipped = 0
    failing_files = set()
    for root, _, files in os.walk(results_dir):
        for name in sorted(files):
            if not name.endswith(".xml"):
                continue
            path = os.path.join(root, name)
            try:
                tree = ET.parse(path)
            except ET.ParseError:
                print(f"unreadable result file: {path}")
                failed += 1
                continue
            for case in tree.iter("testcase"):
                status = case.get("status", "run")
                result = case.get("result", "")
                if status == "notrun" or result == "skipped" or case.find("skipped") is not None:
                    skipped += 1
                elif case.find("failure") is not None or case.find("error") is not None:
                    failed += 1
                    failing_files.add(name)
                    print(f"FAILED: {case.get('classname')}.{case.get('name')} ({name})")
                else:
                    passed += 1
    crashed = 0
    if ctest_rc != 0:
        with open(ctest_log, encoding="utf-8", errors="replace") as log:
            failed_tests = re.findall(r"\d+ - (\S+) \((Failed|SEGFAULT|Timeout|Child aborted|"
                                      r"Exception|Subprocess aborted|[^)]*)\)", log.read())
        for test_name, _ in failed_tests:
            short = test_name.split("_gtest_")[-1]
            if not any(short in f for f in failing_files):
                print(f"FAILED (crashed or no results): {test_name}")
                crashed += 1
        if not failed_tests and failed == 0:
            crashed = 1
    failed += crashed
    if len(sys.argv) > 4:
        check_passed, check_failed = count_checks(sys.argv[4])
        passed += check_passed
        failed += check_failed
    print_wall_times(ctest_log)
    if skipped:
        print(f"{skipped} skipped")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed or passed == 0 else 0


def print_wall_times(ctest_log):
    """The wall time of every test ctest ran (its "Test #N: name ... sec" lines), slowest first."""
    try:
        with open(ctest_log, encoding="utf-8", errors="replace") as log:
            times = re.findall(r"Test +#\d+: (\S+) \.*[^\n]*? ([0-9.]+) sec", log.read())
    except OSError:
        return
    if not times:
        return
    total = sum(float(seconds) for _, seconds in times)
    print(f"wall time per test, slowest first ({len(times)} tests, {total:.0f} s in all):")
    for name, seconds in sorted(times, key=lambda t: -float(t[1])):
        print(f"  {float(seconds):8.1f} s  {name.replace('_ctest_camera_imu_alignment_', '')}")


def count_checks(path):
    """(passed, failed) of the "<check> passed|failed" lines of `path`; a missing or empty file, or
    a line of another form, is one failure."""
    passed = failed = 0
    try:
        with open(path, encoding="utf-8") as checks:
            lines = [line.split() for line in checks if line.strip()]
    except OSError as error:
        print(f"FAILED: checks: cannot read {path} ({error.strerror})")
        return 0, 1
    if not lines:
        print(f"FAILED: checks: no check results in {path}")
        return 0, 1
    for words in lines:
        if len(words) == 2 and words[1] == "passed":
            passed += 1
        elif len(words) == 2 and words[1] == "failed":
            print(f"FAILED: check {words[0]}")
            failed += 1
        else:
            print(f"FAILED: checks: unexpected line '{' '.join(words)}' in {path}")
            failed += 1
    return passed, failed


if __name__ == "__main__":
    sys.exit(main())
