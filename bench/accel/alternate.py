#!/usr/bin/env python3
"""Best-of-N ray throughput, alternating between configurations.

On a shared machine one run of candela-bench can be 15-30% slow for reasons outside the program;
alternating the configurations and keeping each one's best run compares them under the same
conditions. Prints, per configuration, the best and the median Mrays/s per second of the tracing
thread's CPU time (candela-bench --threads 1 reports it).

usage: bench/accel/alternate.py MESH.obj RAYS.rays RUNS CONFIG [CONFIG ...]
  CONFIG: BENCH_BINARY[|ACCEL[|NAME=VALUE ...]]  (ACCEL defaults to kdtree; NAME=VALUE are set in
          the environment of that configuration's runs)
example: bench/accel/alternate.py assets/meshes/bunny.obj /tmp/accel/bunny_bounce.rays 4 \\
             'build-accel/bin/candela-bench|kdtree' 'build-accel/bin/candela-bench|embree'
"""
import os
import re
import statistics
import subprocess
import sys


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    mesh, rays, runs, configs = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4:]
    results = {c: [] for c in configs}
    for _ in range(runs):
        for c in configs:
            parts = c.split('|')
            binary, accel = parts[0], parts[1] if len(parts) > 1 else 'kdtree'
            env = dict(os.environ)
            for kv in parts[2:]:
                k, v = kv.split('=', 1)
                env[k] = v
            out = subprocess.run([binary, mesh, '--rays', rays, '--accel', accel, '--threads', '1', '--repeat', '3'],
                                 capture_output=True, text=True, env=env)
            m = re.search(r'([0-9.]+) Mrays/s per second of thread CPU time', out.stderr)
            if out.returncode != 0 or not m:
                sys.exit(f'{c}: candela-bench failed:\n{out.stderr}')
            results[c].append(float(m.group(1)))
    for c in configs:
        v = results[c]
        print(f'best {max(v):7.3f}  median {statistics.median(v):7.3f}  Mrays/s  {c}')


if __name__ == '__main__':
    main()
