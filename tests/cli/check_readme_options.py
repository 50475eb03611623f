#!/usr/bin/env python3
"""README.md's usage table lists the options that ptr --help lists (those of
src/app/cli_options.def), in the same order, with the same names for their
values. Usage: check_readme_options.py PTR SOURCE_DIR"""
import difflib
import os
import re
import subprocess
import sys

ptr, src = sys.argv[1], sys.argv[2]
# "-o, --output FILE", "--samples N", "--help", "--live [HOST:]PORT",
# "--denoise [QUALITY]": a value's name never starts with '-', and README puts
# optional options in brackets (a value's optional part, "[HOST:]", or an
# optional value, "[QUALITY]", is upper case).
OPTION = re.compile(r"(?:-\w, )?--[a-z][a-z-]*(?: (?!-)(?:\[[A-Z:]+\])?[^\s\[\]]*(?<! ))?")


def help_options():
    text = subprocess.run([ptr, "--help"], check=True, capture_output=True, text=True).stdout
    # An option's line has "-o, --" in column 2 or "--" in column 6 (further
    # lines of a text start in column 24); two spaces end the option.
    return [line.strip().split("  ")[0] for line in text.splitlines()
            if re.match(r"  (-\w, |    )--", line)]


def readme_options():
    with open(os.path.join(src, "README.md"), encoding="utf-8") as f:
        usage = f.read().split("\n## Usage\n", 1)[1].split("\n## ", 1)[0]
    table = usage.split("| option | meaning |\n| --- | --- |\n", 1)[1].split("\n\n", 1)[0]
    options = []
    for row in table.splitlines():
        first_cell = re.split(r"(?<!\\)\|", row)[1].replace("\\|", "|")
        for code in re.findall(r"`([^`]*)`", first_cell):
            options += OPTION.findall(code)
    return options


expected, listed = help_options(), readme_options()
if not expected or listed != expected:
    sys.stdout.writelines(difflib.unified_diff([o + "\n" for o in expected],
                                               [o + "\n" for o in listed],
                                               "ptr --help", "README.md"))
    print("FAIL: README.md's options table is not the options of ptr --help")
    sys.exit(1)
print(f"README.md lists the {len(expected)} options of ptr --help, in order")
