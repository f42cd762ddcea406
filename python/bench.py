"""Times the Python module (not a test; docs/benchmarks.md records its figures):
`import sdfcsg`, evaluate() of 1M points in a scene's bounds on the device and on the CPU (best
of 7, after a first call that builds the kernel), and a first render in a fresh process.

Usage: PYTHONPATH=build/python python3 python/bench.py [SCENE] (default assets/scenes/house.json)"""
import subprocess
import sys
import time

t = time.perf_counter()
import sdfcsg  # noqa: E402
imported = time.perf_counter() - t
import numpy as np  # noqa: E402

path = sys.argv[1] if len(sys.argv) > 1 else "assets/scenes/house.json"
scene = sdfcsg.load(path)
mesh = sdfcsg.mesh(scene, resolution=32)
lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
points = np.random.default_rng(1).uniform(lo, hi, size=(1_000_000, 3)).astype(np.float32)
sdfcsg.evaluate(scene, points, device=True)
best = {True: 1e9, False: 1e9}
for _ in range(7):
    for device in (True, False):
        t = time.perf_counter()
        sdfcsg.evaluate(scene, points, device=device)
        best[device] = min(best[device], time.perf_counter() - t)
print(f"import sdfcsg: {imported * 1000:.0f} ms in the process")
print(f"evaluate 1M points, device: {best[True]:.3f} s ({1 / best[True]:.1f}M points/s)")
print(f"evaluate 1M points, CPU:    {best[False]:.3f} s ({1 / best[False]:.1f}M points/s)")
render = "import sdfcsg; sdfcsg.render(sdfcsg.load(%r), 800, 600)" % path
t = time.perf_counter()
subprocess.run([sys.executable, "-c", render], check=True)
print(f"first render, whole process: {time.perf_counter() - t:.2f} s")
