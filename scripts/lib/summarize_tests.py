#!/usr/bin/python3
"""Counts test cases in JUnit XML results (gtest and rostest) and prints the failed ones.

catkin_test_results counts each gtest case twice (once for <testsuites>, once for <testsuite>),
so the project's summary line is computed here from the <testcase> elements themselves.
Usage: summarize_tests.py RESULTS_DIR  -> prints failures, then "passed failed skipped" last.
"""
import pathlib
import sys
import xml.etree.ElementTree as ET


def main(results_dir):
    passed = failed = skipped = 0
    for xml_file in sorted(pathlib.Path(results_dir).rglob("*.xml")):
        try:
            root = ET.parse(xml_file).getroot()
        except ET.ParseError as error:
            print(f"FAILED {xml_file.name}: unreadable result file ({error})")
            failed += 1
            continue
        cases = list(root.iter("testcase"))
        if not cases and root.get("errors", "0") != "0":
            print(f"FAILED {xml_file.name}: the test did not run (errors={root.get('errors')})")
            failed += 1
        for case in cases:
            name = f"{case.get('classname', '')}.{case.get('name', '')}"
            if case.find("failure") is not None or case.find("error") is not None:
                failed += 1
                print(f"FAILED {name} ({xml_file.name})")
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
            else:
                passed += 1
    print(passed, failed, skipped)


if __name__ == "__main__":
    main(sys.argv[1])
