#!/usr/bin/python3
"""Cross-check of `drover eval ape|rpe` against an independent numpy re-implementation of evo's definitions
(sync.associate_trajectories, geometry.umeyama_alignment, align_trajectory, metrics.APE/RPE, filters, numpy
statistics), on random trajectories with different lengths, clock jitter and a time offset.

Usage: /usr/bin/python3 tests/eval/evo_crosscheck.py PATH/TO/drover [SEED]
Needs numpy (Debian python3-numpy). Prints the worst relative difference; exits non-zero on a mismatch > 1e-9.
Run by hand (not part of ctest); last run: seeds 1-5 agree to < 2e-13.
"""
import json, math, shutil, subprocess, sys, tempfile
import numpy as np
DROVER = sys.argv[1]
rng = np.random.default_rng(int(sys.argv[2]) if len(sys.argv) > 2 else 0)
TMP = tempfile.mkdtemp(prefix="drover_evo_crosscheck_")

def quat_to_R(q):  # x y z w
    x, y, z, w = q
    return np.array([[1-2*(y*y+z*z), 2*(x*y-z*w), 2*(x*z+y*w)],
                     [2*(x*y+z*w), 1-2*(x*x+z*z), 2*(y*z-x*w)],
                     [2*(x*z-y*w), 2*(y*z+x*w), 1-2*(x*x+y*y)]])

def make_traj(n, t0, dt, jitter):
    t = t0 + dt*np.arange(n) + rng.uniform(-jitter, jitter, n)
    t = np.round(t, 6)
    p = np.cumsum(rng.normal(0, 0.3, (n, 3)) + [0.5, 0.1, 0.0], axis=0)
    q = rng.normal(0, 1, (n, 4)); q /= np.linalg.norm(q, axis=1)[:, None]
    # As the file holds them (9 decimals), quaternions normalised again as the reader does.
    p = np.round(p, 9); q = np.round(q, 9)
    return t, p, q

def write_tum(path, t, p, q):
    q[:] = q / np.linalg.norm(q, axis=1)[:, None]  # what the reader makes of the written (rounded) values
    with open(path, "w") as f:
        for i in range(len(t)):
            f.write("%.6f %.9f %.9f %.9f %r %r %r %r\n" % (t[i], *p[i], *q[i]))

def se3(t, p, q):
    out = []
    for i in range(len(t)):
        T = np.eye(4); T[:3, :3] = quat_to_R(q[i]); T[:3, 3] = p[i]; out.append(T)
    return out

def associate(t1, t2, max_diff, offset):
    snd_longer = len(t2) > len(t1)
    short, long_ = (t1, t2) if snd_longer else (t2, t1)
    off = offset if snd_longer else -offset
    ls = long_ + off
    si, li = [], []
    for i, s in enumerate(short):
        d = np.abs(ls - s); j = int(np.argmin(d))
        if d[j] <= max_diff: si.append(i); li.append(j)
    return (si, li) if snd_longer else (li, si)

def umeyama(x, y, with_scale):
    m, n = x.shape
    mx, my = x.mean(axis=1), y.mean(axis=1)
    sx = 1.0/n*np.linalg.norm(x - mx[:, None])**2
    cov = sum(np.outer(y[:, i]-my, x[:, i]-mx) for i in range(n))/n
    u, d, v = np.linalg.svd(cov)
    s = np.eye(m)
    if np.linalg.det(u)*np.linalg.det(v) < 0: s[m-1, m-1] = -1
    r = u.dot(s).dot(v)
    c = 1/sx*np.trace(np.diag(d).dot(s)) if with_scale else 1.0
    return r, my - c*r.dot(mx), c

def align(est, ref, mode):
    if mode == "none": return est
    x = np.array([T[:3, 3] for T in est]).T; y = np.array([T[:3, 3] for T in ref]).T
    r, t, c = umeyama(x, y, mode == "sim3")
    A = np.eye(4); A[:3, :3] = r; A[:3, 3] = t
    out = []
    for T in est:
        S = T.copy(); S[:3, 3] *= c; out.append(A @ S)
    return out

def so3_angle(R):
    return math.acos(max(-1, min(1, (np.trace(R)-1)/2)))

def err(E, rel):
    if rel == "trans": return np.linalg.norm(E[:3, 3])
    if rel == "rot": return np.linalg.norm(E[:3, :3]-np.eye(3))
    if rel == "full": return np.linalg.norm(E-np.eye(4))
    return so3_angle(E[:3, :3])*180/np.pi

def stats(e):
    e = np.array(e)
    return dict(max=np.max(e), min=np.min(e), std=float(np.std(e)), median=np.median(e), mean=float(np.mean(e)),
                rmse=math.sqrt(np.mean(e**2)), sse=np.sum(e**2))

def inv(T): return np.linalg.inv(T)

def run(args):
    r = subprocess.run([DROVER, "-q"] + args + ["--json", TMP + "/out.json"], capture_output=True, text=True)
    if r.returncode != 0: raise SystemExit("drover failed: " + r.stdout + r.stderr)
    return json.load(open(TMP + "/out.json"))

worst = 0.0
for trial in range(6):
    n1, n2 = rng.integers(40, 120), rng.integers(40, 120)
    tr, pr, qr = make_traj(n1, 100.0, 0.1, 0.01)
    te, pe, qe = make_traj(n2, 100.05, 0.1, 0.03)
    write_tum(TMP + "/ref.txt", tr, pr, qr); write_tum(TMP + "/est.txt", te, pe, qe)
    max_diff, offset = 0.04, -0.05
    ir, ie = associate(tr, te, max_diff, offset)
    R = [se3(tr, pr, qr)[i] for i in ir]; E_ = [se3(te, pe, qe)[i] for i in ie]
    for mode in ("none", "se3", "sim3"):
        Ea = align(E_, R, mode)
        for rel in ("trans", "rot", "full", "angle_deg"):
            e = [np.linalg.norm(b[:3, 3]-a[:3, 3]) if rel == "trans" else err(inv(b) @ a, rel) for a, b in zip(Ea, R)]
            want = stats(e)
            got = run(["eval", "ape", TMP + "/ref.txt", TMP + "/est.txt", "--align", mode,
                       "--pose-relation", rel, "--t-max-diff", str(max_diff), "--t-offset", str(offset)])
            assert got["pairs"] == len(ir), (got["pairs"], len(ir))
            for k, v in want.items():
                d = abs(got[k]-v)/max(1.0, abs(v)); worst = max(worst, d)
                assert d < 1e-9, ("ape", mode, rel, k, got[k], v)
            # RPE frames and meters (pairs from the aligned estimate, evo's default)
            for unit, delta in (("frames", 3), ("meters", 2.0)):
                if unit == "frames":
                    ids = list(range(0, len(Ea), delta)); pairs = list(zip(ids, ids[1:]))
                else:
                    ids = []; prev = Ea[0]; path = 0.0
                    for i, T in enumerate(Ea):
                        path += np.linalg.norm(T[:3, 3]-prev[:3, 3]); prev = T
                        if path >= delta: ids.append(i); path = 0.0
                    pairs = list(zip(ids, ids[1:]))
                e = [err(inv(inv(R[i]) @ R[j]) @ (inv(Ea[i]) @ Ea[j]), rel) for i, j in pairs]
                want = stats(e)
                got = run(["eval", "rpe", TMP + "/ref.txt", TMP + "/est.txt", "--align", mode,
                           "--pose-relation", rel, "--t-max-diff", str(max_diff), "--t-offset", str(offset),
                           "--delta", str(delta), "--delta-unit", unit])
                assert got["count"] == len(pairs)
                for k, v in want.items():
                    d = abs(got[k]-v)/max(1.0, abs(v)); worst = max(worst, d)
                    assert d < 1e-9, ("rpe", unit, mode, rel, k, got[k], v)
shutil.rmtree(TMP)
print("all equal; worst relative difference", worst)
