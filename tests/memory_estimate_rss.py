#!/usr/bin/env python3
"""Issue 42 point 4: the memory check's estimate (the log's "memory: ... at least X GB per
rank") covers every large allocation, measured against the peak resident memory (getrusage of
the run) of short runs of jobs/scenes/poiseuille3d.ini (1 thread, 3 steps, averaging from the
start in windows of t_end / 5, so that the Eulerian records' first rows are allocated and
written at once):
  base: the scene as it is (its peak less its estimate: the program, MPI, HDF5);
  bins: output.n_bins = 6000 (per-window records with the 252-field Reynolds-stress budgets);
  lagr: the Lagrangian engine with 2 levels x 2001 lags x 101 release slots.
Each large case: 0.75 <= peak / (estimate + base) <= 1.3 (before, the estimate left the
per-window records and the Lagrangian engine out). And refusals before anything is allocated, exit 1:
  2 ranks on this node whose sum (not each rank's share) is above 80% of the memory: the
  message names the node's ranks and what to do;
  an init.from file whose dimension 'particle' claims 2e9 particles (a few kB on disk): named
  with the key and its size, before it is read.
usage: memory_estimate_rss.py CHANSPH SCENES WORK"""
import os
import re
import subprocess
import sys

chansph, scenes, work = sys.argv[1:4]
scene = os.path.join(scenes, "poiseuille3d.ini")
os.makedirs(work, exist_ok=True)
env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1",
           OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
fails = []


def run(label, sets, cmd=None):
    args = (cmd or []) + [chansph, "run", scene, "--out", os.path.join(work, label), "--overwrite",
                          "--max-steps", "3"]
    for s in ["output.t_average_start=0", "output.stats_every=1", "stats.window=2.4"] + sets:
        args += ["--set", s]
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    out = p.stdout.read()
    _, status, ru = os.wait4(p.pid, 0)
    m = re.search(r"need at least ([0-9.e+-]+) GB per rank", out)
    return (float(m.group(1)) * 1e9 if m else float("nan"), ru.ru_maxrss * 1024.0,
            os.waitstatus_to_exitcode(status), out)


est0, peak0, rc, out = run("base", [])
base = peak0 - est0
print("base: estimate %.1f MB, peak RSS %.1f MB (exit %d): %.1f MB not in the estimate"
      % (est0 / 1e6, peak0 / 1e6, rc, base / 1e6))
if rc != 75:
    sys.exit("FAIL: the base run exited %d:\n%s" % (rc, out[-800:]))
for label, sets in (("bins", ["output.n_bins=6000"]),
                    ("lagr", ["lagrangian.y_plus=1,2", "lagrangian.n_lags=2000",
                              "lagrangian.horizon=0.1", "lagrangian.release_every=0.001"])):
    est, peak, rc, out = run(label, sets)
    r = peak / (est + base)
    print("%s: estimate %.1f MB, peak RSS %.1f MB (exit %d): peak / (estimate + base) = %.2f"
          % (label, est / 1e6, peak / 1e6, rc, r))
    if rc != 75 or not 0.75 <= r <= 1.3:
        fails.append("%s: peak / (estimate + base) %.2f outside 0.75 .. 1.3 (exit %d)" % (label, r, rc))
# two ranks of this node, each within 80% of the memory, together above it
kb = next(int(l.split()[1]) for l in open("/proc/meminfo") if l.startswith("MemTotal:"))
per_bin = 46.4e3  # bytes of the bins case per bin (2 x 8 rows of the records), about
bins = int(0.55 * kb * 1e3 / per_bin)
est, peak, rc, out = run("ranks", ["output.n_bins=%d" % bins, "domain.lx=0.8"],  # 2 blocks fit
                         ["mpirun", "--oversubscribe", "-np", "2"])
msg = next((l for l in out.splitlines() if "error" in l), "")
print("2 ranks, output.n_bins = %d: exit %d: %s" % (bins, rc, msg))
if rc != 1 or not re.search(r"need at least .* GB per MPI rank .* GB for the 2 ranks on this node\), "
                            r"more than the .* GB \(80%\) .*: use fewer ranks per node", msg):
    fails.append("2 ranks whose sum is above 80%% of the memory: exit %d" % rc)
# an init.from that claims 2e9 particles
big = os.path.join(work, "claims_2e9.nc")
subprocess.run(["/usr/bin/python3", "-c", """
import sys, netCDF4
d = netCDF4.Dataset(sys.argv[1], "w")
d.createDimension("particle", 2000000000)
for v in "x y z u v w rho mass".split():
    d.createVariable(v, "f8", ("particle",), chunksizes=(1 << 20,))
d.createVariable("id", "i8", ("particle",), chunksizes=(1 << 20,))
d.close()
""", big], check=True)
est, peak, rc, out = run("claims", ["init.from=" + big])
msg = next((l for l in out.splitlines() if "error" in l), "")
print("init.from of %d bytes claiming 2e9 particles: exit %d, peak RSS %.1f MB: %s"
      % (os.path.getsize(big), rc, peak / 1e6, msg))
if rc != 1 or "key 'init.from': this rank's share of the 2e+09 particles of %s need at least 512 GB" % big not in msg:
    fails.append("init.from claiming 2e9 particles: exit %d" % rc)
sys.exit("FAIL: " + "; ".join(fails) if fails else 0)
