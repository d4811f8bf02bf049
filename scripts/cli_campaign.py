#!/usr/bin/python3
"""Attack campaign against the `conform` command line around its model importer.

Runs N random command lines from a fixed seed, each inside a throw-away "home" folder full of
the user's own files, over the surfaces a user can get wrong or an attacker can choose:

  --out values   ., .., ancestors, the input's folder, a non-empty folder of the user's, a file,
                 names holding $(...), backquotes, quotes, ';' and newlines, earlier results
  scalpel CSVs   mutants of a good one (extra or missing cells, junk numbers, header only),
                 a FIFO, /dev/zero, a folder
  scene files    mutants of the built-in scenes' JSON, a FIFO, /dev/zero, a folder
  numbers        ik, skin --frames, tear --open at the extremes
  signals        SIGINT, SIGTERM or SIGHUP at a random time during a run
  concurrency    two runs into one --out at once

After each run it checks, and counts as a defect:

  touched   a file of the user's outside the run's own --out changed, appeared or vanished
            (an --out that would hold the user's files is no --out of the run's at all)
  injected  a sentinel file that the injected commands would create exists
  orphan    a process started by the run is still alive after it ended (found by an
            environment tag that every child inherits)
  staging   a .NAME.staging-PID folder or .NAME.lock file is left behind
  mismatch  the exit code does not match the outcome: 0 without a complete result (or with a
            non-finite number in it), a failure that changed the earlier result (unless it
            was swapped in as incomplete, exit 1, with its failures in summary.json), a signalled
            run that did not exit with 128 + signal (or 0, when it finished first)
  hang      still running after --limit seconds without printing progress (killed); a run
            still stepping then is counted as slow_valid (a mutant asking for a large mesh)
  memory    peak resident memory above --max-rss-mb on a non-model input

Deterministic for a given --seed (apart from signal timing). Exit status 0 when no defect was
found, 1 otherwise. `scripts/cli_campaign.py --runs 3000` is the campaign of the closing note;
tests/cli/cli_campaign_test.sh runs a small budget in the suite.

Usage: scripts/cli_campaign.py --conform build/scenes/conform [--runs 3000] [--seed 7]
                               [--jobs 2] [--limit 10] [--max-rss-mb 512] [--keep DIR]
"""
import argparse
import collections
import concurrent.futures
import hashlib
import json
import math
import os
import random
import re
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time

SENTINEL = "PWNED"
TAG = "CONFORM_CAMPAIGN_TAG"
GOOD_SCALPEL = ("t,ax,ay,az,bx,by,bz\n"
                "0,0.02,-0.05,0.18,0.02,0.05,0.18\n"
                "0.5,0.02,-0.05,0.25,0.02,0.05,0.25\n"
                "1,0.02,-0.05,0.32,0.02,0.05,0.32\n")
INJECTIONS = ["r$(touch {s})", "r`touch {s}`", "r'$(touch {s})'", 'r"`touch {s}`"',
              "r;touch {s}", "r\ntouch {s}", "r && touch {s}", "r|touch {s}", "r $(touch {s}) q",
              "r\\\"$(touch {s})\\\"", "r%{s}%s", "r'\"'; touch {s}"]
SCENES = ["membrane-slit", "membrane-edge", "membrane-hole", "membrane-patch", "cut", "drill", "tear-opening", "arm-track", "character"]


def snapshot(root):
    """Path -> (kind, size, digest) of everything under root."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            path = os.path.join(dirpath, name)
            try:
                st = os.lstat(path)
            except FileNotFoundError:
                continue
            if stat.S_ISREG(st.st_mode):
                with open(path, "rb") as f:
                    digest = hashlib.blake2b(f.read(), digest_size=8).hexdigest()
                out[path] = ("file", st.st_size, digest)
            elif stat.S_ISDIR(st.st_mode):
                out[path] = ("dir", 0, "")
            else:
                out[path] = ("other", 0, str(st.st_mode))
    return out


def inside(path, folder):
    return path == folder or path.startswith(folder.rstrip("/") + "/")


def tagged_processes(tag):
    """Pids of live processes whose environment holds TAG=tag."""
    needle = f"{TAG}={tag}".encode()
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/environ", "rb") as f:
                env = f.read().split(b"\0")
            with open(f"/proc/{entry}/stat", "rb") as f:
                state = f.read().rsplit(b")", 1)[1].split()[0]
        except OSError:
            continue
        if needle in env and state != b"Z":
            pids.append(int(entry))
    return pids


class Sandbox:
    """A user's home: inputs, documents, a working folder; runs start in home/a/work."""

    def __init__(self, root, rng):
        self.root = root
        self.home = os.path.join(root, "home")
        self.work = os.path.join(self.home, "a", "work")
        self.inputs = os.path.join(self.home, "inputs")
        self.rng = rng
        self.results = set()  # folders that a successful run wrote: a run may replace them
        for d in (self.work, self.inputs, os.path.join(self.home, "docs", "deep"),
                  os.path.join(self.home, "empty")):
            os.makedirs(d, exist_ok=True)
        files = {
            os.path.join(self.work, "notes.txt"): b"the user's notes\n",
            os.path.join(self.home, "a", "thesis.tex"): b"\\section{mine}\n",
            os.path.join(self.home, "docs", "deep", "data.csv"): b"1,2,3\n",
            os.path.join(self.home, "docs", "readme"): b"keep\n",
            os.path.join(self.inputs, "scalpel.csv"): GOOD_SCALPEL.encode(),
        }
        for path, data in files.items():
            with open(path, "wb") as f:
                f.write(data)
        shutil.copy("/usr/share/assimp/models/OBJ/box.obj", os.path.join(self.inputs, "cube.obj"))
        shutil.copy("/usr/share/assimp/models/OBJ/box.obj", os.path.join(self.work, "cube.obj"))
        os.mkfifo(os.path.join(self.inputs, "fifo"))

    def out_value(self, kind):
        """An --out value, and the folder it names (absolute; None for no --out)."""
        r = self.rng.random()
        if r < 0.30:
            value = self.rng.choice(["out1", "out2", "res/deep/out3", os.path.join(self.home, "abs")])
        elif r < 0.55:
            value = self.rng.choice([".", "./", "..", "../..", "../work", "../../a", "../../inputs",
                                     "../../docs", "../../docs/deep", "../../empty",
                                     "../../a/thesis.tex", "notes.txt", self.home, self.work])
        elif r < 0.85:
            value = self.rng.choice(INJECTIONS).format(s=os.path.join(self.root, SENTINEL))
        else:
            value = None if kind == "run" else "out1"
        return value

    def resolve(self, value, default):
        path = default if value is None else value
        return os.path.normpath(os.path.join(self.work, path))

    def may_write(self, folder, before):
        """Whether a run may put its results at `folder`: a fresh name, an empty folder, or a
        result of an earlier run; never a place that holds or contains the user's things."""
        if folder in self.results:
            return True
        for path in before:
            if inside(path, folder) and path != folder:
                return False
            if inside(folder, path) and before[path][0] != "dir":
                return False  # a file on the way
        return True


def scalpel_input(rng, box):
    """A scalpel argument: mostly mutants of the good CSV, some non-files."""
    r = rng.random()
    if r < 0.08:
        return rng.choice(["/dev/zero", os.path.join(box.inputs, "fifo"), box.inputs,
                           "/nonexistent.csv"]), True
    rows = GOOD_SCALPEL.splitlines()
    if r < 0.4:
        return os.path.join(box.inputs, "scalpel.csv"), False
    mutations = [
        lambda rs: rs[:1],                                              # header only
        lambda rs: [rs[0]] + [x + ",9,9" for x in rs[1:]],             # extra cells
        lambda rs: [rs[0]] + [",".join(x.split(",")[:5]) for x in rs[1:]],  # missing cells
        lambda rs: [rs[0]] + [x.replace("0.02", "0abc", 1) for x in rs[1:]],
        lambda rs: [rs[0]] + [x.replace("0.05", rng.choice(["nan", "inf", "1e308", "-1e400",
                                                            "", " ", "0x1p3", "1e-320"]), 1)
                              for x in rs[1:]],
        lambda rs: [rs[0]] + rs[1:] * rng.randint(2, 50),              # times not increasing
        lambda rs: ["t;ax;ay;az;bx;by;bz"] + [x.replace(",", ";") for x in rs[1:]],
        lambda rs: [rs[0]] + ["\0\0\0"] + rs[1:],
        lambda rs: [rs[0].upper()] + rs[1:],
        lambda rs: [],
    ]
    text = "\n".join(rng.choice(mutations)(rows)) + rng.choice(["\n", "", "\r\n"])
    path = os.path.join(box.root, f"scalpel_{rng.randrange(1 << 30)}.csv")
    with open(path, "w") as f:
        f.write(text)
    return path, True


def scene_input(rng, box, builtins):
    """A scene argument: a built-in name, or a mutated scene file."""
    r = rng.random()
    if r < 0.35:
        return rng.choice(SCENES), False
    if r < 0.43:
        return rng.choice(["/dev/zero", os.path.join(box.inputs, "fifo"), box.inputs,
                           "/nonexistent.json"]), True
    name = rng.choice(sorted(builtins))
    scene = json.loads(builtins[name])
    mutate_json(scene, rng)
    text = json.dumps(scene)
    if rng.random() < 0.15:
        text = text[:rng.randrange(len(text))]
    path = os.path.join(box.root, f"scene_{rng.randrange(1 << 30)}.json")
    with open(path, "w") as f:
        f.write(text)
    return path, True


def mutate_json(node, rng, depth=0):
    """Changes one to three leaves of a scene: a number to an extreme, a type to another."""
    for _ in range(rng.randint(1, 3)):
        target, key = pick_leaf(node, rng)
        if target is None:
            return
        choice = rng.random()
        if choice < 0.5:
            target[key] = rng.choice([0, -1, 1e308, -1e308, 1e-320, 1e9, 2.5, 10 ** 6, 3])
        elif choice < 0.7:
            target[key] = rng.choice(["", "x", None, [], {}, True, "$(touch PWNED)"])
        elif choice < 0.85 and isinstance(target, dict):
            del target[key]
        else:
            target[key + "_typo" if isinstance(key, str) else key] = 1


def pick_leaf(node, rng):
    path_node, key = None, None
    current = node
    for _ in range(6):
        if isinstance(current, dict) and current:
            k = rng.choice(sorted(current))
        elif isinstance(current, list) and current:
            k = rng.randrange(len(current))
        else:
            break
        path_node, key = current, k
        current = current[k]
        if rng.random() < 0.4:
            break
    return path_node, key


def plan(rng, box, builtins):
    """One trial: the argv, the --out folder it names, and what to expect."""
    r = rng.random()
    trial = {"signal": None, "concurrent": False, "non_model": False, "out_value": None}
    if r < 0.10:
        target = [str(rng.choice([0.3, 0.0, 1e300, -1e-320])), "0", str(rng.choice([0.2, 5.0]))]
        upper = rng.choice(["0.3", "1e300", "1e-320", "0", "-1", "1e-9"])
        trial.update(argv=["ik", "--target", *target, "--upper", upper, "--json"], out=None,
                     non_model=True)
        return trial
    if r < 0.16:
        frames = rng.choice(["2", "3", "2147483647", "100000000", "-1", "0"])
        out = os.path.join(box.work, "skin", "pose.ply")
        trial.update(argv=["skin", "arm:1", "--frames", frames, "--out", out], out=None,
                     skin_out=out, non_model=True)
        return trial
    value = box.out_value("run" if r >= 0.55 else "mesh")
    trial["out_value"] = value
    if r < 0.30:
        model = rng.choice(["arm:1", os.path.join(box.inputs, "cube.obj"), "cube.obj"])
        argv = ["cut", model, "--plane", "0", "0", "1", rng.choice(["0.3", "0.5", "1e300"])]
        argv += ["--cap"] if rng.random() < 0.5 else []
    elif r < 0.38:
        argv = ["drill", "arm:1", "--tip", "0", "-0.1", "0.3", "--base", "0", "0.1", "0.3",
                "--radius", rng.choice(["0.01", "1e-320", "0", "1e300"])]
    elif r < 0.55:
        scalpel, odd = scalpel_input(rng, box)
        argv = ["tear", "arm:1", "--scalpel", scalpel]
        if rng.random() < 0.3:
            argv += ["--open", rng.choice(["0.01", "1e308", "0", "-1"])]
        trial["non_model"] = odd
    else:
        scene, odd = scene_input(rng, box, builtins)
        argv = ["run", scene]
        if rng.random() < 0.7:  # short runs; the others run whole, with their edits and plots
            argv += ["--steps", str(rng.choice([2, 3, 5]))]
        if rng.random() < 0.85:
            argv.append("--no-render")
        trial["non_model"] = odd
        trial["scene"] = scene
    default = os.path.join("results", "SCENE")
    if value is not None:
        argv += ["--out", value]
    elif argv[0] == "run":
        default = os.path.join("results", scene_name(argv[1], builtins))
    trial["argv"] = argv
    trial["out"] = box.resolve(value, default)
    if argv[0] == "run" and rng.random() < 0.25:
        trial["signal"] = (rng.choice([signal.SIGINT, signal.SIGTERM, signal.SIGHUP]),
                           rng.uniform(0.05, 1.5))
    elif rng.random() < 0.08:
        trial["concurrent"] = True
    return trial


def scene_name(arg, builtins):
    """The default result's name: a built-in scene's name, or a scene file's stem."""
    if arg in builtins:
        return arg
    return os.path.splitext(os.path.basename(arg))[0]


def launch(conform, argv, cwd, tag, logs):
    """Starts a run with its output in files (a pipe nobody reads could block it)."""
    env = dict(os.environ, **{TAG: tag})
    env.pop("DISPLAY", None)
    out = tempfile.TemporaryFile(dir=logs)
    err = tempfile.TemporaryFile(dir=logs)
    proc = subprocess.Popen([conform, *argv], cwd=cwd, env=env, stdin=subprocess.DEVNULL,
                            stdout=out, stderr=err, start_new_session=True)
    proc.logs = (out, err)
    return proc


def read_log(f, most=1 << 20):
    f.seek(0)
    data = f.read(most)
    f.close()
    return data


def wait(proc, limit):
    """(returncode, peak RSS in MiB, hung, stdout, stderr) of a started run."""
    deadline = time.monotonic() + limit
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            out, err = read_log(proc.logs[0]), read_log(proc.logs[1])
            proc.returncode = os.waitstatus_to_exitcode(status)
            return proc.returncode, usage.ru_maxrss / 1024, False, out, err
        if time.monotonic() > deadline:
            os.killpg(proc.pid, signal.SIGKILL)
            _, status, usage = os.wait4(proc.pid, 0)
            err = read_log(proc.logs[1])
            read_log(proc.logs[0])
            return None, usage.ru_maxrss / 1024, True, b"", err
        time.sleep(0.01)


def result_complete(trial, folder):
    if not os.path.isdir(folder):
        return False
    names = os.listdir(folder)
    if trial["argv"][0] == "run":
        if "summary.json" not in names:
            return False
        with open(os.path.join(folder, "summary.json")) as f:
            text = f.read()
        return finite_json(text)
    return bool(names)


def recorded_failure(folder):
    """Whether `folder` is a run swapped in as incomplete: its summary lists its failures."""
    try:
        with open(os.path.join(folder, "summary.json")) as f:
            return bool(json.load(f).get("failures"))
    except (OSError, ValueError, AttributeError):
        return False


def finite_json(text):
    try:
        json.loads(text, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
    except ValueError:
        return False
    return "null" not in text.replace('"null"', "")


def run_trial(conform, box, trial, index, limit, max_rss):
    """Runs one trial and returns the list of its defects (names)."""
    before = snapshot(box.home)
    out = trial["out"]
    may = out is not None and box.may_write(out, before)
    tag = f"{os.getpid()}-{box.root}-{index}"
    procs = [launch(conform, trial["argv"], box.work, tag, box.root)]
    if trial["concurrent"]:
        procs.append(launch(conform, trial["argv"], box.work, tag, box.root))
    sig = trial["signal"]
    if sig:
        time.sleep(sig[1])
        if os.waitid(os.P_PID, procs[0].pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is None:
            os.kill(procs[0].pid, sig[0])  # still running (WNOWAIT: not reaped here)
    started = time.monotonic()
    results = [wait(p, limit) for p in procs]
    trial["seconds"] = time.monotonic() - started
    defects = []
    # A run past the limit that was still stepping (its progress lines) is a slow valid scene,
    # e.g. a mutant asking for the 23k-node arm; one that printed no progress is a hang. Either
    # is killed with SIGKILL, whose staging only the next run into that folder can remove.
    killed = [r for r in results if r[2]]
    if any(b"% (step" not in r[4] for r in killed):
        defects.append("hang")
    elif killed:
        trial["slow"] = True
    if trial["non_model"] and max(r[1] for r in results) > max_rss:
        defects.append("memory")
    for _ in range(200):  # children killed by the parent-death signal die asynchronously
        left = tagged_processes(tag)
        if not left:
            break
        time.sleep(0.01)
    if left:
        defects.append("orphan")
        for pid in left:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
    if os.path.exists(os.path.join(box.root, SENTINEL)) or any(
            SENTINEL in n and n.startswith(SENTINEL) for n in os.listdir(box.work)):
        defects.append("injected")
        remove(os.path.join(box.root, SENTINEL))
    after = snapshot(box.home)
    allowed = out if may else None
    changed = [p for p in set(before) | set(after)
               if before.get(p) != after.get(p) and not (allowed and inside(p, allowed))]
    leftovers = [p for p in after if ".staging-" in os.path.basename(p)
                 or os.path.basename(p).endswith(".lock")]
    if leftovers and not killed:
        defects.append("staging")
    if leftovers:
        for p in leftovers:  # counted once: the next trial starts clean
            remove(p)
    changed = [p for p in changed if p not in leftovers and not inside_any(p, leftovers)]
    if allowed:  # the folders on the way to a new --out are the run's to make
        changed = [p for p in changed if not (p not in before and after.get(p, ("",))[0] == "dir"
                                              and inside(allowed, p))]
    if trial.get("skin_out"):
        changed = [p for p in changed if not inside(p, os.path.dirname(trial["skin_out"]))]
    if changed:
        defects.append("touched")
    defects += exit_mismatches(trial, results, before, after, out, may)
    ok = [r for r in results if r[0] == 0]
    if ok and out is not None:
        box.results.add(out)
    return defects, results


def inside_any(path, folders):
    return any(inside(path, f) for f in folders)


def exit_mismatches(trial, results, before, after, out, may):
    """Whether every exit code says what happened."""
    defects = []
    sig = trial["signal"]
    for rc, _, hung, stdout, _ in results:
        if hung:
            continue
        if rc == 0:
            if trial["argv"][0] == "ik" and not finite_json(stdout.decode(errors="replace")):
                defects.append("mismatch")
            if out is not None and (not may or not result_complete(trial, out)):
                defects.append("mismatch")
        elif sig and rc == -sig[0] and sig[1] < 0.2:
            pass  # killed before main() installed its handlers: nothing was written yet
        elif sig and rc not in (128 + sig[0], 1, 2):
            defects.append("mismatch")
        elif not sig and rc >= 128:
            defects.append("mismatch")  # a crash
    if out is not None and all(r[0] not in (0, None) for r in results) and not (
            1 in [r[0] for r in results] and recorded_failure(out)):
        earlier = {p: v for p, v in before.items() if inside(p, out)}
        now = {p: v for p, v in after.items() if inside(p, out)}
        if earlier != now:
            defects.append("mismatch")  # a failed run changed the earlier result
    return defects


def remove(path):
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path, ignore_errors=True)
    elif os.path.lexists(path):
        os.remove(path)


def worker(args, worker_index, count, builtins):
    rng = random.Random(args.seed * 1000 + worker_index)
    counts = collections.Counter()
    reasons = collections.Counter()
    examples = []
    root = tempfile.mkdtemp(prefix=f"conform-campaign-{worker_index}-")
    box = Sandbox(root, rng)
    for i in range(count):
        if i and i % 150 == 0:  # a fresh home now and then keeps the disk bounded
            shutil.rmtree(root, ignore_errors=True)
            root = tempfile.mkdtemp(prefix=f"conform-campaign-{worker_index}-")
            box = Sandbox(root, rng)
        trial = plan(rng, box, builtins)
        defects, results = run_trial(args.conform, box, trial, i, args.limit, args.max_rss_mb)
        counts["runs"] += 1
        counts["ok" if results[0][0] == 0 else "refused"] += 1
        if results[0][0] not in (0, None):
            reasons[refusal_reason(results[0][4])] += 1
        counts["signalled"] += 1 if trial["signal"] else 0
        counts["longest_run_s"] = max(counts["longest_run_s"], trial["seconds"])
        counts["slow_valid"] += 1 if trial.get("slow") else 0
        counts["concurrent"] += 1 if trial["concurrent"] else 0
        counts["peak_rss_mb_non_model"] = max(
            counts["peak_rss_mb_non_model"],
            max(r[1] for r in results) if trial["non_model"] else 0)
        for d in set(defects):
            counts[d] += 1
            if len(examples) < 40:
                examples.append({"defect": d, "argv": trial["argv"],
                                 "rc": [r[0] for r in results],
                                 "stderr": results[0][4].decode(errors="replace")[-300:]})
    if not args.keep:
        shutil.rmtree(root, ignore_errors=True)
    return counts, examples, reasons


def refusal_reason(stderr):
    """The last line of a refused run's stderr, without paths and numbers: what refused it."""
    lines = [x for x in stderr.decode(errors="replace").splitlines() if x.strip()]
    line = lines[-1] if lines else "(nothing on stderr)"
    line = re.sub(r"/\S*", "PATH", line)
    return re.sub(r"[-+]?\d[\d.e+-]*", "N", line)[:90]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--conform", default="build/scenes/conform")
    parser.add_argument("--runs", type=int, default=3000)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--limit", type=float, default=10.0)
    parser.add_argument("--max-rss-mb", type=float, default=512.0)
    parser.add_argument("--keep", action="store_true", help="keep the sandboxes")
    parser.add_argument("--json", help="write the counts and examples here")
    args = parser.parse_args()
    args.conform = os.path.abspath(args.conform)
    builtins = {}
    for name in SCENES:
        shown = subprocess.run([args.conform, "scenes", "--show", name], capture_output=True)
        if shown.returncode == 0:
            builtins[name] = shown.stdout.decode()
    start = time.monotonic()
    shares = [args.runs // args.jobs + (1 if k < args.runs % args.jobs else 0)
              for k in range(args.jobs)]
    total, examples, reasons = collections.Counter(), [], collections.Counter()
    # Threads, not processes: a worker spends its time waiting for its runs, and anything that
    # killed a worker would then kill the campaign itself, visibly, instead of breaking a pool.
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(worker, args, k, n, builtins) for k, n in enumerate(shares)]
        for f in futures:
            counts, ex, why = f.result()
            reasons.update(why)
            maxima = {k: max(total[k], counts[k]) for k in ("peak_rss_mb_non_model", "longest_run_s")}
            total.update(counts)  # adds the counts; the maxima are set below
            for k, v in maxima.items():
                total[k] = v
            examples += ex
    defects = ["touched", "injected", "orphan", "staging", "mismatch", "hang", "memory"]
    report = {"seed": args.seed, "seconds": round(time.monotonic() - start, 1),
              **{k: total[k] for k in ["runs", "ok", "refused", "signalled", "concurrent",
                                       "slow_valid"]},
              **{d: total[d] for d in defects},
              "peak_rss_mb_non_model": round(total["peak_rss_mb_non_model"], 1),
              "longest_run_s": round(total["longest_run_s"], 1),
              "refusals": dict(reasons.most_common(25)), "examples": examples}
    print(json.dumps({k: v for k, v in report.items() if k not in ("examples", "refusals")},
                     indent=1))
    for e in examples[:15]:
        print(json.dumps(e))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)
    return 1 if any(total[d] for d in defects) else 0


if __name__ == "__main__":
    sys.exit(main())
