#!/usr/bin/env python3
"""Self-test of tools/check_house.py: runs it on a copy of tests/house/fixture/ (plus files made
here: an outside reference, a file over 900 lines, functions over 150 lines), and checks that
each rule reports exactly what it should and stays quiet on the clean parts. Run by CTest."""
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
CHECK = os.path.join(REPO, "tools", "check_house.py")


def long_function(name, lines):
    body = "".join(f"    x += {i};\n" for i in range(lines - 3))
    return f"int {name}(int x) {{\n{body}    return x;\n}}\n"


def main():
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        root = os.path.join(tmp, "repo")
        shutil.copytree(os.path.join(HERE, "fixture"), root)
        # Made here so the repository itself holds no citation and no oversized file.
        with open(os.path.join(root, "shaders", "reference.glsl")) as f:
            text = f.read().replace("REFERENCE", "DESIGN " + "\u00a7" + "4")
        with open(os.path.join(root, "shaders", "reference.glsl"), "w") as f:
            f.write(text)
        with open(os.path.join(root, "docs", "notes.md"), "a") as f:
            f.write("See " + "iss" + "ue 12 for the figures.\n")
            # Any case: a sentence opening with the citation is still one.
            f.write("The " + "se" + "ed's rule: fall back to the coarsest level.\n")
            f.write("As shown in THE " + "ta" + "lk, tiles are classified first.\n")
        with open(os.path.join(root, "src", "cited.cpp"), "w") as f:
            f.write("// The " + "SE" + "ED's measure: 1.5 bits per shadel.\nint cited = 0;\n")
        with open(os.path.join(root, "src", "big.cpp"), "w") as f:
            f.write("int big = 0;\n" * 901)
        with open(os.path.join(root, "src", "long.cpp"), "w") as f:
            f.write("namespace shadel {\n" + long_function("tooLong", 151) +
                    long_function("justRight", 150) + "}\n")
        with open(os.path.join(root, "src", "listed.cpp"), "w") as f:
            f.write(long_function("listedLong", 200))

        run = subprocess.run([sys.executable, CHECK, root], capture_output=True, text=True)
        out = run.stdout.splitlines()

        def expect(fragment, why):
            if not any(fragment in line for line in out):
                failures.append(f"missing ({why}): {fragment}")

        def refuse(fragment, why):
            hits = [line for line in out if fragment in line]
            if hits:
                failures.append(f"unexpected ({why}): {hits[0]}")

        if run.returncode != 1:
            failures.append(f"exit code {run.returncode}, expected 1")
        expect("shaders/reference.glsl:1: reference:", "a design-brief citation in a shader")
        expect("docs/notes.md:5: reference:", "an issue number in docs")
        expect("docs/notes.md:4: names: the doc names `vanishedDocName`", "a stale name in docs")
        refuse("docs/notes.md:3", "a random seed is not a citation")
        expect("docs/notes.md:6: reference:", "a seed document cited in sentence case")
        expect("docs/notes.md:7: reference:", "a talk cited in capitals")
        expect("src/cited.cpp:1: reference:", "a seed document cited in a C++ comment")
        expect("src/big.cpp:1: size: 901 lines", "a file over 900 lines")
        expect("src/long.cpp:2: size: function tooLong is 151 lines", "a function over 150 lines")
        refuse("justRight", "a function of exactly 150 lines")
        refuse("listedLong", "a listed exception")
        expect("house_exceptions.txt:2: exceptions: src/gone.cpp vanished", "a stale exception")
        expect("src/stale.cpp:1: names: comment names `oldName`", "a stale backticked name")
        expect("src/stale.cpp:1: names: comment names `renamedThing()`", "a stale name() call")
        expect("src/stale.cpp:1: names: comment names staleCamelName", "a stale camelCase name")
        expect("src/stale.cpp:1: names: comment names the file gone_file.glsl", "a missing file")
        refuse("src/clean.cpp", "flags, file names, JSON keys and allowed names")
        refuse("VkImage", "a Vulkan name in docs")
        refuse("ab77a3e", "a commit id in docs")
        if len(out) != 13:
            failures.append(f"{len(out)} lines reported, expected 13:\n  " + "\n  ".join(out))

        # A tree without violations passes.
        for name in ("big.cpp", "long.cpp", "stale.cpp", "cited.cpp"):
            os.remove(os.path.join(root, "src", name))
        os.remove(os.path.join(root, "shaders", "reference.glsl"))
        os.remove(os.path.join(root, "docs", "notes.md"))
        with open(os.path.join(root, "tools", "house_exceptions.txt"), "w") as f:
            f.write("function src/listed.cpp listedLong -- a listed exception\n")
        clean = subprocess.run([sys.executable, CHECK, root], capture_output=True, text=True)
        if clean.returncode != 0:
            failures.append("the clean tree failed:\n" + clean.stdout)

    for f in failures:
        print("check_house self-test:", f)
    print("check_house self-test:", "FAILED" if failures else "passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
