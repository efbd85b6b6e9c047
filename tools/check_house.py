#!/usr/bin/env python3
"""The house check: rules the repository keeps, checked in CI (scripts/test.sh).

  references   nothing in the repository cites a document outside it (a design brief, talk
               notes, an issue tracker): every comment and doc says what is, in its own words.
  size         no file in src/ over 900 lines, no function in src/ over 150 lines, except the
               ones listed with a reason in tools/house_exceptions.txt.
  names        every `backticked` identifier and every name() call in a C++ or GLSL comment
               names something that exists in the code of src/, shaders/ or tests/ (comments
               stripped, string literals kept, so flags, JSON keys and scene names count), so a
               rename leaves no stale comment behind. Paths, file names, flags and anything
               with spaces are recognised and skipped; the rest of the exceptions are listed in
               tools/house_allowed_names.txt. camelCase words in comments are held to the same
               rule, and a source file a comment names (foo.glsl, dir/bar.h) must exist.
               The docs (docs/, README.md, OVERVIEW.md) are held to it for backticked names.

Usage: check_house.py [ROOT]   (ROOT defaults to the repository holding this script)
Prints one line per violation, "path:line: rule: message", and exits 1 when there is any.
Standard library only.
"""
import os
import re
import sys

MAX_FILE_LINES = 900
MAX_FUNCTION_LINES = 150

# Folders and top-level files the rules look at, relative to the root.
REFERENCE_SCOPE = ["src", "shaders", "tests", "docs", "bench", "fuzz", "scripts", "cmake",
                   "README.md", "OVERVIEW.md", "CMakeLists.txt"]
NAME_SCOPE = ["src", "shaders", "tests", "bench", "fuzz"]
CODE_SCOPE = ["src", "shaders", "tests", "bench", "fuzz"]
SIZE_SCOPE = ["src"]

TEXT_SUFFIXES = (".cpp", ".h", ".hpp", ".glsl", ".comp", ".frag", ".vert", ".geom", ".tesc",
                 ".tese", ".mesh", ".task", ".rgen", ".rchit", ".rmiss", ".md", ".txt", ".py",
                 ".sh", ".cmake", ".json", ".in")
COMMENTED_SUFFIXES = (".cpp", ".h", ".hpp", ".glsl", ".comp", ".frag", ".vert", ".geom",
                      ".tesc", ".tese", ".mesh", ".task", ".rgen", ".rchit", ".rmiss")
CPP_SUFFIXES = (".cpp", ".h", ".hpp")

# Citations of documents outside the repository. Written so that random-number seeds, hex
# constants and the word "issue" in prose do not match.
REFERENCE_PATTERNS = [
    (re.compile(r"DESIGN\s*§"), "cites the design brief by section"),
    (re.compile(r"DESIGN\.md"), "cites the design brief"),
    (re.compile(r"\bseeds?\s+0\d\d"), "cites a seed document"),
    (re.compile(r"\bseeds?/"), "cites the seed folder"),
    (re.compile(r"\(seeds?:"), "cites a seed document"),
    (re.compile(r"\bseed(?:'s)?\s*:\s*\""), "quotes a seed document"),
    (re.compile(r"\bthe seed(?:'s)?\b(?!\s*(?:of|value|for|is|=|\())", re.IGNORECASE),
     "cites a seed document"),
    (re.compile(r"\bseed's\b", re.IGNORECASE), "cites a seed document"),
    (re.compile(r"\bthe talks?\b", re.IGNORECASE), "cites a talk"),
    (re.compile(r"\b[Ii]ssues?\s+\d+"), "cites an issue number"),
    (re.compile(r"\bOxide\b"), "names a talk"),
    (re.compile(r"Agents of Mayhem"), "names a talk"),
    (re.compile(r"\bRumbleverse\b"), "names a talk"),
    (re.compile(r"\b4A\b(?!\w)"), "names a talk"),
]

SKIP_DIRS = {".git", "build", "build-asan", "build-fuzz", "__pycache__", "third_party",
             "external", "_deps"}


# The self-test's fixture tree breaks the rules on purpose (tests/house/test_check_house.py).
SKIP_PATHS = {os.path.join("tests", "house", "fixture")}


def repo_files(root, scope):
    for entry in scope:
        path = os.path.join(root, entry)
        if os.path.isfile(path):
            yield entry
        elif os.path.isdir(path):
            for dirpath, dirnames, filenames in os.walk(path):
                dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS and
                                     os.path.relpath(os.path.join(dirpath, d), root)
                                     not in SKIP_PATHS)
                for name in sorted(filenames):
                    full = os.path.join(dirpath, name)
                    yield os.path.relpath(full, root)


def read_text(root, rel):
    try:
        with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as f:
            return f.read()
    except OSError:
        return None


def split_comments(text):
    """Returns (code, comments) of C/C++/GLSL source, both the same length as text with the
    other part blanked (newlines kept, so offsets give line numbers). Strings stay in code."""
    code, comments = list(text), [c if c == "\n" else " " for c in text]
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == "/" and i + 1 < n and text[i + 1] == "/":
            j = text.find("\n", i)
            j = n if j < 0 else j
        elif c == "/" and i + 1 < n and text[i + 1] == "*":
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
        elif c == '"' or c == "'":
            if c == "'" and i > 0 and (text[i - 1].isalnum()):  # digit separator 1'000
                i += 1
                continue
            if c == '"' and i > 0 and text[i - 1] == "R":  # raw string R"d( ... )d"
                m = re.match(r'"([^(\s]*)\(', text[i:])
                if m:
                    end = text.find(")" + m.group(1) + '"', i)
                    i = n if end < 0 else end + len(m.group(1)) + 2
                    continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            i = j + 1
            continue
        else:
            i += 1
            continue
        for k in range(i, j):
            if text[k] != "\n":
                comments[k] = text[k]
                code[k] = " "
        i = j
    return "".join(code), "".join(comments)


def line_of(text, offset):
    return text.count("\n", 0, offset) + 1


# --- rule: references ----------------------------------------------------------------------

def check_references(root, skip):
    out = []
    for rel in repo_files(root, REFERENCE_SCOPE):
        if not rel.endswith(TEXT_SUFFIXES) or rel in skip:
            continue
        text = read_text(root, rel)
        if text is None:
            continue
        for number, line in enumerate(text.split("\n"), 1):
            for pattern, why in REFERENCE_PATTERNS:
                m = pattern.search(line)
                if m:
                    out.append(f"{rel}:{number}: reference: {why}: \"{m.group(0)}\"")
                    break
    return out


# --- rule: size ----------------------------------------------------------------------------

def load_exceptions(path):
    """Lines 'file PATH -- reason' or 'function PATH NAME -- reason'; # starts a comment."""
    files, functions, problems = {}, {}, []
    if not os.path.exists(path):
        return files, functions, problems
    with open(path, encoding="utf-8") as f:
        for number, raw in enumerate(f, 1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            head, sep, reason = line.partition("--")
            words = head.split()
            if not sep or not reason.strip():
                problems.append(f"{path}:{number}: exceptions: every entry needs '-- reason'")
            elif len(words) == 2 and words[0] == "file":
                files[words[1]] = number
            elif len(words) == 3 and words[0] == "function":
                functions[(words[1], words[2])] = number
            else:
                problems.append(f"{path}:{number}: exceptions: expected 'file PATH -- reason' "
                                "or 'function PATH NAME -- reason'")
    return files, functions, problems


NOT_A_FUNCTION = re.compile(r"^\s*(?:template\s*<[^{]*>\s*)?(?:typedef\s+)?"
                            r"(?:struct|class|enum|union|namespace|extern)\b")
CONTROL = re.compile(r"^\s*(?:if|for|while|switch|do|else|try|catch|return)\b")


def functions_in(code):
    """Yields (name, first line, line count) of every function body at namespace or class
    scope in C++ code with comments already blanked. Strings are blanked here too."""
    code = re.sub(r'"(?:[^"\\\n]|\\.)*"', lambda m: '""' + " " * (len(m.group(0)) - 2), code)
    code = re.sub(r"^\s*#.*$", lambda m: " " * len(m.group(0)), code, flags=re.M)
    stack = []  # per open brace: "scope" (namespace/class/other outer) or "function"/"inner"
    header_start = 0
    i, n = 0, len(code)
    while i < n:
        c = code[i]
        if c == "{":
            inside_function = any(kind in ("function", "inner") for kind, _ in stack)
            header = code[header_start:i]
            kind = "inner" if inside_function else "scope"
            if not inside_function:
                flat = " ".join(header.split())
                if ("(" in flat and not NOT_A_FUNCTION.match(flat) and not CONTROL.match(flat)
                        and not flat.rstrip().endswith("=") and "=" not in flat.split("(")[0]):
                    kind = "function"
            stack.append((kind, i))
            header_start = i + 1
        elif c == "}":
            if stack:
                kind, start = stack.pop()
                if kind == "function":
                    header = code[:start]
                    cut = max(header.rfind(";"), header.rfind("}"), header.rfind("{"))
                    sig = " ".join(header[cut + 1:].split())
                    m = re.search(r"([~\w]+(?:::[~\w]+)*)\s*(?:<[^()]*>)?\s*\(", sig)
                    name = m.group(1).split("::")[-1] if m else "?"
                    first = line_of(code, cut + 1 + len(header[cut + 1:]) -
                                    len(header[cut + 1:].lstrip()))
                    last = line_of(code, i)
                    yield name, line_of(code, start), last - line_of(code, start) + 1
            header_start = i + 1
        elif c == ";":
            header_start = i + 1
        i += 1


def check_size(root, exceptions_path):
    files, functions, out = load_exceptions(exceptions_path)
    used_files, used_functions = set(), set()
    for rel in repo_files(root, SIZE_SCOPE):
        if not rel.endswith(CPP_SUFFIXES + COMMENTED_SUFFIXES):
            continue
        text = read_text(root, rel)
        if text is None:
            continue
        lines = text.count("\n") + (0 if text.endswith("\n") else 1)
        if lines > MAX_FILE_LINES:
            if rel in files:
                used_files.add(rel)
            else:
                out.append(f"{rel}:1: size: {lines} lines (limit {MAX_FILE_LINES}); split it "
                           "or list it in tools/house_exceptions.txt with a reason")
        if not rel.endswith(CPP_SUFFIXES):
            continue
        code, _ = split_comments(text)
        for name, first, count in functions_in(code):
            if count <= MAX_FUNCTION_LINES:
                continue
            if (rel, name) in functions:
                used_functions.add((rel, name))
            else:
                out.append(f"{rel}:{first}: size: function {name} is {count} lines (limit "
                           f"{MAX_FUNCTION_LINES}); split it or list it in "
                           "tools/house_exceptions.txt with a reason")
    rel_exc = os.path.relpath(exceptions_path, root)
    for path, number in files.items():
        if path not in used_files:
            out.append(f"{rel_exc}:{number}: exceptions: {path} is within the limit now; "
                       "remove its entry")
    for key, number in functions.items():
        if key not in used_functions:
            out.append(f"{rel_exc}:{number}: exceptions: {key[0]} {key[1]} is within the limit "
                       "now (or gone); remove its entry")
    return out


# --- rule: names ---------------------------------------------------------------------------

BACKTICKED = re.compile(r"`([^`\n]+)`")
CALLED = re.compile(r"(?<![\w.:>-])((?:[A-Za-z_]\w*::)*[A-Za-z_]\w*)\(\)")
IDENTIFIER_CHAIN = re.compile(r"^[A-Za-z_]\w*(?:(?:::|\.|->)[A-Za-z_~]\w*)*(?:\(\))?$")
FILE_LIKE = re.compile(r"\.(?:h|hpp|cpp|glsl|comp|frag|vert|json|png|gltf|glb|md|txt|py|sh|csv|"
                       r"spv|hdr|exr|ktx2?|jpg|jpeg|bin|cmake|log|ini)$", re.I)


def code_words(root):
    words = set()
    for rel in repo_files(root, CODE_SCOPE):
        if not rel.endswith(TEXT_SUFFIXES):
            continue
        text = read_text(root, rel)
        if text is None:
            continue
        if rel.endswith(COMMENTED_SUFFIXES):
            text, _ = split_comments(text)
        elif rel.endswith((".py", ".sh", ".cmake", ".txt")):
            text = re.sub(r"#.*", "", text) if not rel.endswith(".txt") else text
        words.update(re.findall(r"\w+", text))
    return words


# Names a comment or doc may use that belong to the graphics APIs or are placeholders, not to
# this repository: Vulkan and GLSL built-ins, commit ids, NAME_N patterns.
EXTERNAL_NAME = re.compile(r"^(?:gl_\w+|[Vv]k[A-Z]\w*|VK_\w+|SPV_\w+|GL_\w+|[0-9a-f]{7,40}|\w+_N)$")


def load_allowed(path):
    allowed = set()
    if os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            for raw in f:
                line = raw.split("#", 1)[0].strip()
                if line:
                    allowed.add(line.split()[0])
    return allowed


def names_in_comment(comment):
    """Identifier-looking names a comment refers to: backticked tokens and name() calls. Each
    yields the components that must exist (the parts of a::b.c chains)."""
    found = []
    for m in BACKTICKED.finditer(comment):
        token = m.group(1).strip()
        if (not IDENTIFIER_CHAIN.match(token) or FILE_LIKE.search(token.rstrip("()"))
                or token.startswith("-")):
            continue
        found.append((token, m.start()))
    for m in CALLED.finditer(comment):
        found.append((m.group(1) + "()", m.start()))
    for token, offset in found:
        parts = [p for p in re.split(r"::|\.|->", token.rstrip("()").lstrip("~")) if p]
        yield token, parts, offset


CAMEL = re.compile(r"(?<![\w/.`-])([a-z]+[A-Z]\w*)\b")
SOURCE_FILE = re.compile(r"(?<![\w/.-])([\w./-]*\w\w\.(?:h|hpp|cpp|glsl|comp|frag|vert))\b(?!\.\w)")


def file_names(root):
    names = set()
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = [d for d in dirnames if d not in (".git", "__pycache__")
                       and not d.startswith("build")]
        names.update(filenames)
    return names


DOC_SCOPE = ["docs", "README.md", "OVERVIEW.md"]


def check_names(root, allowed_path):
    words = code_words(root)
    files = file_names(root)
    words |= {os.path.splitext(f)[0] for f in files}  # a file's stem: `render_command`
    allowed = load_allowed(allowed_path)
    out = []
    # Docs: backticked names and name() calls only (prose has camelCase words of its own).
    for rel in repo_files(root, DOC_SCOPE):
        if not rel.endswith(".md"):
            continue
        text = read_text(root, rel) or ""
        for number, line in enumerate(text.split("\n"), 1):
            for token, parts, _ in names_in_comment(line):
                missing = [p for p in parts if p not in words and p not in allowed
                           and not EXTERNAL_NAME.match(p)]
                if missing and token not in allowed:
                    out.append(f"{rel}:{number}: names: the doc names `{token}`, but "
                               f"{', '.join(missing)} is not in the code")
    for rel in repo_files(root, NAME_SCOPE):
        if not rel.endswith(COMMENTED_SUFFIXES):
            continue
        text = read_text(root, rel)
        if text is None:
            continue
        _, comments = split_comments(text)
        for number, line in enumerate(comments.split("\n"), 1):
            seen = set()
            for token, parts, _ in names_in_comment(line):
                seen.update(parts)
                missing = [p for p in parts if p not in words and p not in allowed
                           and not EXTERNAL_NAME.match(p)]
                if missing and token not in allowed:
                    out.append(f"{rel}:{number}: names: comment names `{token}`, but "
                               f"{', '.join(missing)} is not in the code")
            # camelCase words read as identifiers even without backticks.
            for m in CAMEL.finditer(line):
                word = m.group(1)
                if word not in words and word not in allowed and word not in seen:
                    seen.add(word)
                    out.append(f"{rel}:{number}: names: comment names {word}, which is not in "
                               "the code")
            # A source file a comment names exists somewhere in the repository.
            for m in SOURCE_FILE.finditer(line):
                path = m.group(1)
                if (os.path.basename(path) not in files and path not in allowed
                        and os.path.basename(path) not in allowed):
                    out.append(f"{rel}:{number}: names: comment names the file {path}, which "
                               "does not exist")
    return out


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.abspath(argv[1]) if len(argv) > 1 else os.path.dirname(here)
    tools = os.path.join(root, "tools")
    skip = {"tools/check_house.py"}
    violations = []
    violations += check_references(root, skip)
    violations += check_size(root, os.path.join(tools, "house_exceptions.txt"))
    violations += check_names(root, os.path.join(tools, "house_allowed_names.txt"))
    for v in violations:
        print(v)
    if violations:
        print(f"check_house: {len(violations)} violation(s)", file=sys.stderr)
        return 1
    print("check_house: clean")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
