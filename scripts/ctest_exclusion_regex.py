#!/usr/bin/env python3
"""Prints a ctest -E regular expression matching exactly the test names listed in a file (one a
line, '#' comments), and warns on stderr about names the build directory's ctest does not know,
so that a renamed test is noticed rather than silently kept out.
    ctest_exclusion_regex.py LIST_FILE BUILD_DIR"""
import json
import re
import subprocess
import sys

list_file, build_dir = sys.argv[1], sys.argv[2]
names = [line.strip() for line in open(list_file, encoding="utf-8")
         if line.strip() and not line.lstrip().startswith("#")]
listing = subprocess.run(["ctest", "--test-dir", build_dir, "--show-only=json-v1"],
                         check=True, capture_output=True, text=True).stdout
known = {test["name"] for test in json.loads(listing)["tests"]}
for name in names:
    if name not in known:
        print(f"{list_file}: no test named \"{name}\" (renamed? update the list)", file=sys.stderr)
# CMake's regular expressions: a backslash escapes any of these.
special = re.compile(r"([\^$.\[\]*+?()|\\])")
print("|".join("^" + special.sub(r"\\\1", n) + "$" for n in names if n in known))
