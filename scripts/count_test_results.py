#!/usr/bin/env python3
"""Counts test cases in gtest/rostest XML result files and prints "N passed, N failed".

Usage: count_test_results.py RESULTS_DIR CTEST_EXIT_CODE CTEST_LOG
A test executable that ctest reports as failed but whose XML shows no failing case (it crashed or
timed out before writing its results) counts as one failure. Exits 1 on any failure or on no tests.
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
    line = f"{passed} passed, {failed} failed"
    if skipped:
        line += f", {skipped} skipped"
    print(line)
    return 1 if failed or passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
