#!/usr/bin/env python3
"""Mutation check for shadel's test suite.

Each entry of mutations.json names a file, an exact snippet of it (which must occur exactly once),
its replacement, a one-line description and the tests that should catch the change. For each
mutation the tool applies it, rebuilds incrementally, runs the named tests with a timeout and
records whether a test failed (caught), none did (survived), the build failed or the run timed
out. The mutated file is restored afterwards, also on Ctrl-C, SIGTERM or an exception, and the
tool checks with git that no mutated file is left changed.

Usage (from the repository root, after a normal build of build/):
  python3 tools/mutation/mutate.py --list
  python3 tools/mutation/mutate.py --check            # stale-snippet check only, no build
  python3 tools/mutation/mutate.py --baseline         # the named tests pass on the clean tree
  python3 tools/mutation/mutate.py [--only ID,ID] [--out DIR] [--timeout S]

Results go to DIR (default build/mutation): results.json and results.md, rewritten after every
mutation so an interrupted run keeps what it measured.
"""
import argparse
import fnmatch
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "mutations.json")
TARGETS = ["shadel_gpu_tests", "shadel_unit_tests", "shadel"]
BINARIES = {"gpu": "build/tests/shadel_gpu_tests", "unit": "build/tests/shadel_unit_tests"}
FIELDS = ("id", "file", "find", "replace", "description", "tests")


class Terminated(Exception):
    pass


def on_sigterm(signum, frame):
    raise Terminated()


def load():
    with open(DATA) as f:
        entries = json.load(f)["mutations"]
    problems = []
    seen = set()
    for e in entries:
        missing = [k for k in FIELDS if k not in e]
        if missing:
            problems.append(f"{e.get('id', '?')}: missing {', '.join(missing)}")
        if e.get("id") in seen:
            problems.append(f"{e['id']}: duplicate id")
        seen.add(e.get("id"))
        if e.get("suite", "gpu") not in BINARIES:
            problems.append(f"{e['id']}: suite must be gpu or unit")
    if problems:
        sys.exit("mutations.json: " + "; ".join(problems))
    return entries


def stale_reason(e):
    """Why an entry cannot be applied, or None."""
    path = os.path.join(ROOT, e["file"])
    if not os.path.isfile(path):
        return f"{e['file']} does not exist"
    with open(path, encoding="utf-8") as f:
        text = f.read()
    n = text.count(e["find"])
    if n != 1:
        return f"snippet occurs {n} times in {e['file']} (must be once)"
    if e["find"] == e["replace"]:
        return "replacement equals the snippet"
    return None


def write_atomic(path, text):
    d = os.path.dirname(path)
    os.makedirs(d, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=d, prefix=".tmp-")
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def run(cmd, timeout, env=None, log=None):
    """Runs cmd in its own process group; returns (exit code or None on timeout, seconds, output)."""
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         start_new_session=True, text=True, errors="replace")
    try:
        out, _ = p.communicate(timeout=timeout)
        rc = p.returncode
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, _ = p.communicate()
        rc = None
    except BaseException:
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()
        raise
    if log:
        with open(log, "a") as f:
            f.write(f"$ {' '.join(cmd)}\n{out}\n")
    return rc, time.monotonic() - t0, out


def build(timeout, log):
    return run(["cmake", "--build", "build", "-j2", "--target"] + TARGETS, timeout, log=log)


def test_command(e):
    binary = BINARIES[e.get("suite", "gpu")]
    return [binary, "--gtest_filter=" + e["tests"]]


# Sources whose output the bake and environment caches keep (keyed by their inputs, not by the
# code): a mutation there runs with empty caches, or it would read what the clean code wrote.
CACHED_STAGES = ("src/bake/", "src/render/environment/")


def run_tests(e, timeout, scratch, log):
    """The entry's tests, with GALLIVM_PERF=nopt. The caches (SHADEL_CACHE_DIR, and TMPDIR, where
    the GPU tests keep theirs) are the run's scratch, shared by its mutations, or fresh and
    removed after for a mutation of a cached stage."""
    env = dict(os.environ)
    env["GALLIVM_PERF"] = "nopt"
    fresh = e.get("file", "").startswith(CACHED_STAGES)
    tmp = os.path.join(scratch, "tmp-" + e["id"] if fresh else "tmp")
    if fresh:
        shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(os.path.join(tmp, "cache"), exist_ok=True)
    env["TMPDIR"] = tmp
    env["SHADEL_CACHE_DIR"] = os.path.join(tmp, "cache")
    env.pop("GTEST_FILTER", None)
    try:
        return run(test_command(e), timeout, env=env, log=log)
    finally:
        if fresh:
            shutil.rmtree(tmp, ignore_errors=True)


def count_ran(out):
    for line in out.splitlines():
        if line.startswith("[==========]") and "ran." in line:
            try:
                return int(line.split()[1])
            except ValueError:
                return None
    return None


def failed_tests(out):
    """The failed tests' names (a parameterised test's line adds ", where GetParam() = ...")."""
    names = []
    for line in out.splitlines():
        if not line.startswith("[  FAILED  ] ") or "listed below" in line:
            continue
        name = line[len("[  FAILED  ] "):].split(", where")[0].split(" (")[0].strip()
        if name and " " not in name and name not in names:
            names.append(name)
    return names


def list_tests(binary):
    """Every test name of a GoogleTest binary (--gtest_list_tests)."""
    out = subprocess.run([binary, "--gtest_list_tests"], cwd=ROOT, capture_output=True,
                         text=True, env=dict(os.environ, GALLIVM_PERF="nopt")).stdout
    names, suite = [], ""
    for line in out.splitlines():
        if not line.strip() or line.startswith(("Note:", "[")):
            continue
        if not line.startswith(" "):
            suite = line.split("#")[0].strip()
        else:
            names.append(suite + line.split("#")[0].strip())
    return names


def unmatched_patterns(entries):
    """(id, pattern) of every filter pattern that names no test: a mutation whose tests do not
    exist would only ever survive."""
    bad = []
    for suite, binary in BINARIES.items():
        mine = [e for e in entries if e.get("suite", "gpu") == suite]
        if not mine:
            continue
        names = list_tests(os.path.join(ROOT, binary))
        for e in mine:
            for pattern in e["tests"].split("-")[0].split(":"):
                if pattern and not any(fnmatch.fnmatchcase(n, pattern) for n in names):
                    bad.append((e["id"], pattern))
    return bad


def classify(rc, out):
    if rc is None:
        return "timeout"
    ran = count_ran(out)
    if ran == 0:
        return "no tests"
    if rc == 77:
        return "skipped"
    return "survived" if rc == 0 else "caught"


def mutate_one(e, args, log):
    path = os.path.join(ROOT, e["file"])
    result = {"id": e["id"], "file": e["file"], "description": e["description"],
              "tests": e["tests"], "suite": e.get("suite", "gpu")}
    reason = stale_reason(e)
    if reason:
        result.update(result="stale", detail=reason, build_s=0.0, test_s=0.0)
        return result
    with open(path, encoding="utf-8") as f:
        original = f.read()
    try:
        with open(path, "w", encoding="utf-8") as f:
            f.write(original.replace(e["find"], e["replace"], 1))
        rc, build_s, out = build(args.build_timeout, log)
        result["build_s"] = round(build_s, 1)
        if rc != 0:
            result.update(result="build failed" if rc is not None else "build timeout",
                          test_s=0.0, detail=out.strip().splitlines()[-1:] and
                          out.strip().splitlines()[-1][:200])
            return result
        rc, test_s, out = run_tests(e, args.timeout, args.scratch, log)
        result["test_s"] = round(test_s, 1)
        result["result"] = classify(rc, out)
        result["ran"] = count_ran(out)
        result["failed"] = failed_tests(out)
        return result
    finally:
        with open(path, "w", encoding="utf-8") as f:
            f.write(original)


def markdown(results, wall):
    caught = sum(r["result"] == "caught" for r in results)
    lines = [f"caught {caught} of {len(results)} (wall time {wall / 60:.1f} min)", "",
             "| id | mutates | file | tests | result | build s | test s |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in results:
        tests = r["tests"].replace("|", "\\|")
        lines.append(f"| {r['id']} | {r['description']} | {r['file']} | `{tests}` | "
                     f"{r['result']} | {r.get('build_s', 0):.0f} | {r.get('test_s', 0):.0f} |")
    counts = {}
    for r in results:
        counts[r["result"]] = counts.get(r["result"], 0) + 1
    lines += ["", ", ".join(f"{k}: {v}" for k, v in sorted(counts.items()))]
    return "\n".join(lines) + "\n"


def previous_results(out_dir):
    try:
        with open(os.path.join(out_dir, "results.json")) as f:
            return json.load(f).get("results", [])
    except (OSError, ValueError):
        return []


def save(results, out_dir, wall, started, earlier=None):
    """results.json and results.md; with `earlier` (--merge), the earlier run's results of the
    entries not run now are kept, in mutations.json's order."""
    if earlier is not None:
        now = {r["id"]: r for r in results}
        order = [e["id"] for e in load()]
        merged = {r["id"]: r for r in earlier}
        merged.update(now)
        results = [merged[i] for i in order if i in merged]
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                            capture_output=True, text=True).stdout.strip()
    write_atomic(os.path.join(out_dir, "results.json"),
                 json.dumps({"started_utc": started, "wall_s": round(wall, 1), "commit": commit,
                             "results": results}, indent=1) + "\n")
    write_atomic(os.path.join(out_dir, "results.md"), markdown(results, wall))


def dirty(files):
    rc = subprocess.run(["git", "diff", "--quiet", "--"] + sorted(files), cwd=ROOT).returncode
    return rc != 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--list", action="store_true", help="list the mutations and exit")
    ap.add_argument("--check", action="store_true", help="report stale entries and exit")
    ap.add_argument("--baseline", action="store_true",
                    help="run every entry's tests on the unmutated tree (they must pass)")
    ap.add_argument("--only", help="comma-separated ids")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "mutation"))
    ap.add_argument("--scratch", default=os.path.join(tempfile.gettempdir(), "shadel-mutation"))
    ap.add_argument("--timeout", type=float, default=600, help="seconds per test run")
    ap.add_argument("--build-timeout", type=float, default=1200, help="seconds per build")
    ap.add_argument("--merge", action="store_true",
                    help="keep the other entries' results of an earlier run in --out (with --only)")
    ap.add_argument("--no-final-build", action="store_true",
                    help="skip the rebuild of the restored tree at the end")
    args = ap.parse_args()

    entries = load()
    if args.only:
        want = args.only.split(",")
        unknown = [w for w in want if w not in {e["id"] for e in entries}]
        if unknown:
            print(f"mutate.py: unknown id(s): {', '.join(unknown)}", file=sys.stderr)
            return 2
        entries = [e for e in entries if e["id"] in want]

    if args.list:
        for e in entries:
            print(f"{e['id']:<28} {e['file']:<44} {e['description']}  [{e['tests']}]")
        return 0
    if args.check:
        bad = [(e["id"], stale_reason(e)) for e in entries if stale_reason(e)]
        for i, why in bad:
            print(f"stale {i}: {why}")
        print(f"{len(entries) - len(bad)} of {len(entries)} entries apply")
        return 1 if bad else 0

    files = {e["file"] for e in entries if os.path.isfile(os.path.join(ROOT, e["file"]))}
    if dirty(files):
        print("mutate.py: files to mutate have uncommitted changes; commit or stash them first",
              file=sys.stderr)
        return 2
    signal.signal(signal.SIGTERM, on_sigterm)
    os.makedirs(args.out, exist_ok=True)
    shutil.rmtree(args.scratch, ignore_errors=True)  # caches of an earlier run: start empty
    os.makedirs(args.scratch, exist_ok=True)
    log = os.path.join(args.out, "baseline.log" if args.baseline else "run.log")
    open(log, "a" if args.merge else "w").close()
    started = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    t0 = time.monotonic()

    if args.baseline:
        # One run per test binary over the union of the entries' filters: every named test must
        # pass on the clean tree, or a "caught" would mean nothing.
        rc, s, out = build(args.build_timeout, log)
        if rc != 0:
            print("mutate.py: the clean tree does not build", file=sys.stderr)
            return 1
        bad = 0
        for i, pattern in unmatched_patterns(entries):
            print(f"baseline {i}: the filter pattern {pattern} names no test", flush=True)
            bad += 1
        for suite in sorted({e.get("suite", "gpu") for e in entries}):
            filters = []
            for e in entries:
                if e.get("suite", "gpu") == suite:
                    filters += [f for f in e["tests"].split(":") if f not in filters]
            union = {"id": "baseline-" + suite, "suite": suite, "tests": ":".join(filters)}
            rc, s, out = run_tests(union, args.timeout * 4, args.scratch, log)
            state = classify(rc, out)
            failed = failed_tests(out)
            bad += state != "survived"
            print(f"baseline {suite}: {count_ran(out)} tests in {s:.0f} s: "
                  f"{'all pass' if state == 'survived' else state + ' ' + str(failed)}", flush=True)
        return 1 if bad else 0

    earlier = previous_results(args.out) if args.merge else None
    results = []
    try:
        for i, e in enumerate(entries, 1):
            print(f"[{i}/{len(entries)}] {e['id']}: {e['description']} ...", flush=True)
            r = mutate_one(e, args, log)
            results.append(r)
            extra = f" ({', '.join(r['failed'][:3])})" if r.get("failed") else ""
            extra += f" [{r['detail']}]" if r.get("detail") else ""
            print(f"[{i}/{len(entries)}] {e['id']}: {r['result']}  build {r.get('build_s', 0):.0f} s"
                  f", tests {r.get('test_s', 0):.0f} s{extra}", flush=True)
            save(results, args.out, time.monotonic() - t0, started, earlier)
    except (KeyboardInterrupt, Terminated):
        print("mutate.py: interrupted; the mutated file is restored", file=sys.stderr)
    finally:
        if dirty(files):
            print("mutate.py: ERROR a mutated file is still changed (git diff)", file=sys.stderr)
            return 1
        if not args.no_final_build:
            print("rebuilding the restored tree ...", flush=True)
            build(args.build_timeout, log)
    wall = time.monotonic() - t0
    save(results, args.out, wall, started, earlier)
    caught = sum(r["result"] == "caught" for r in results)
    print(f"caught {caught} of {len(results)}; wall time {wall / 60:.1f} min; "
          f"results in {os.path.relpath(args.out, ROOT)}/results.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
