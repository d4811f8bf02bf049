#!/usr/bin/env python3
"""Mutation campaign against the model import path of `conform`.

Makes N mutants of each seed model (truncation, byte flips, zero runs, special numbers,
duplicated runs, deletions), runs `conform info`, `cut` and `drill` on each with a time limit,
and counts the outcomes:

  ok       exit status 0
  refused  exit status 1..127 with a message on stderr (a clean error)
  crash    killed by a signal or exit status >= 128
  hang     still running at the limit (killed)

A crash or hang is a defect; the mutants that caused them are kept in OUT/defects/ with the
command line, to become regression inputs. Deterministic for a given --seed. Not a test (it
takes minutes); `scripts/fuzz_models.py --mutants 300` is the campaign of the closing note.

Usage: scripts/fuzz_models.py [--conform build/scenes/conform] [--mutants 300] [--jobs 2]
                              [--limit 20] [--import-seconds 5] [--out /tmp/conform-fuzz]
                              [--commands info,cut,drill]
A reader that spins on a mutant is stopped by the command's own --import-seconds cap (a clean
error); only a command still running at --limit counts as a hang.
"""
import argparse
import collections
import concurrent.futures
import os
import random
import shutil
import subprocess
import sys

MODELS = "/usr/share/assimp/models/"
SEEDS = [
    "glTF2/simple_skin/simple_skin.gltf",
    "glTF/BoxTextured-glTF-Binary/BoxTextured.glb",
    "OFF/Cube.off",
    "MD5/SimpleCube.md5mesh",
    "FBX/animation_with_skeleton.fbx",
    "Collada/box_nested_animation.dae",
    "OBJ/box_longline.obj",
    "X/test_cube_text.x",
    "PLY/cube_uv.ply",
    "SMD/triangle.smd",
    "STL/triangle_with_two_solids.stl",
    "3DS/RotatingCube.3DS",
]
SPECIALS = [b"nan", b"-nan", b"inf", b"1e308", b"-1e308", b"9999999", b"-1", b"0",
            b"4294967295", b"\xff\xff\xff\xff", b"\x00\x00\xc0\x7f"]


def mutate(data: bytes, rng: random.Random) -> bytes:
    """One to three random edits of `data`."""
    out = bytearray(data)
    for _ in range(rng.randint(1, 3)):
        if not out:
            break
        kind = rng.randrange(6)
        at = rng.randrange(len(out))
        if kind == 0:  # truncation
            del out[at:]
        elif kind == 1:  # byte flips
            for _ in range(rng.randint(1, 16)):
                i = rng.randrange(len(out))
                out[i] ^= 1 << rng.randrange(8)
        elif kind == 2:  # a run of zeros
            n = rng.randint(1, 64)
            out[at:at + n] = bytes(min(n, len(out) - at))
        elif kind == 3:  # a special number, over what was there
            s = rng.choice(SPECIALS)
            out[at:at + len(s)] = s
        elif kind == 4:  # a duplicated run
            n = rng.randint(1, 256)
            out[at:at] = out[at:at + n]
        else:  # a deletion
            del out[at:at + rng.randint(1, 64)]
    return bytes(out)


def command_line(conform, command, model, out_dir, import_seconds):
    cap = ["--import-seconds", str(import_seconds)]
    if command == "info":
        return [conform, "info", model] + cap
    if command == "cut":
        return [conform, "cut", model, "--plane", "0", "0", "1", "0", "--cap", "--out", out_dir] + cap
    return [conform, "drill", model, "--tip", "0", "0", "1", "--base", "0", "0", "-1",
            "--radius", "0.2", "--out", out_dir] + cap


def run_one(job):
    conform, command, model, out_dir, limit, import_seconds = job
    argv = command_line(conform, command, model, out_dir, import_seconds)
    p = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        _, err = p.communicate(timeout=limit)
    except subprocess.TimeoutExpired:
        p.kill()  # the process only: its import child must die with it (orphans are counted)
        p.communicate()
        return "hang", argv, ""
    shutil.rmtree(out_dir, ignore_errors=True)
    rc = p.returncode
    if rc == 0:
        return "ok", argv, ""
    if rc < 0 or rc >= 128:
        return "crash", argv, err.decode(errors="replace")[-400:]
    return "refused" if err.strip() else "silent", argv, err.decode(errors="replace")[-400:]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--conform", default="build/scenes/conform")
    ap.add_argument("--mutants", type=int, default=300)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--limit", type=float, default=20.0, help="seconds per command (a hang)")
    ap.add_argument("--import-seconds", type=float, default=5.0,
                    help="the commands' own cap on reading the file (--import-seconds)")
    ap.add_argument("--out", default="/tmp/conform-fuzz")
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--commands", default="info,cut,drill")
    a = ap.parse_args()
    conform = os.path.abspath(a.conform)
    shutil.rmtree(a.out, ignore_errors=True)
    os.makedirs(os.path.join(a.out, "mutants"))
    os.makedirs(os.path.join(a.out, "defects"))
    rng = random.Random(a.seed)
    jobs = []
    for seed in SEEDS:
        data = open(MODELS + seed, "rb").read()
        ext = os.path.splitext(seed)[1]
        for i in range(a.mutants):
            path = os.path.join(a.out, "mutants", f"{os.path.basename(seed)}.{i}{ext}")
            with open(path, "wb") as f:
                f.write(mutate(data, rng))
            for command in a.commands.split(","):
                jobs.append((conform, command, path, path + "." + command + ".out", a.limit,
                             a.import_seconds))
    counts = collections.defaultdict(collections.Counter)
    defects = []
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        for (outcome, argv, err), job in zip(pool.map(run_one, jobs), jobs):
            fmt = os.path.splitext(job[2])[1].lower()
            counts[(fmt, job[1])][outcome] += 1
            if outcome in ("crash", "hang", "silent"):
                kept = os.path.join(a.out, "defects", os.path.basename(job[2]))
                shutil.copy(job[2], kept)
                defects.append(f"{outcome}: {' '.join(argv)}\n    {err.strip()}")
    print(f"{'format':10} {'command':7} {'ok':>5} {'refused':>8} {'crash':>6} {'hang':>5} {'silent':>7}")
    total = collections.Counter()
    for (fmt, command), c in sorted(counts.items()):
        total.update(c)
        print(f"{fmt:10} {command:7} {c['ok']:5} {c['refused']:8} {c['crash']:6} {c['hang']:5} "
              f"{c['silent']:7}")
    print(f"{'all':10} {'':7} {total['ok']:5} {total['refused']:8} {total['crash']:6} "
          f"{total['hang']:5} {total['silent']:7}")
    # Import children left running after their parent ended (killed at the limit, or crashed).
    ps = subprocess.run(["pgrep", "-f", os.path.join(a.out, "mutants")], capture_output=True, text=True)
    orphans = [line for line in ps.stdout.split() if line.strip()]
    print(f"orphaned processes: {len(orphans)}")
    if orphans:
        defects.append(f"orphans: {len(orphans)} processes still running ({' '.join(orphans)})")
    with open(os.path.join(a.out, "defects.txt"), "w") as f:
        f.write("\n".join(defects) + "\n")
    if defects:
        print(f"{len(defects)} defects; inputs in {a.out}/defects, commands in {a.out}/defects.txt")
    return 1 if defects else 0


if __name__ == "__main__":
    sys.exit(main())
