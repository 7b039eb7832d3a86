#!/usr/bin/env python3
"""Python benchmark of the roboticplatform module (issue 16): single-call and batched forward
kinematics, Jacobian and inverse dynamics (RNEA) of the Puma 560 and the WAM 7 from Python, next
to PyKDL in the same run; the batched call per row next to the C++ loop (model_bench's *_rp/6 and
*_rp/7 figures, run here); and a batched call in two Python threads next to two in sequence (the
GIL released), for each arm.

Run: PYTHONPATH=build/python python3 bench/python_bench.py [--model-bench build/bin/model_bench]
Figures, not assertions: see docs/python.md.
"""
import argparse
import json
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import PyKDL as K

import roboticplatform as rp

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))
import kdl_reference  # noqa: E402


def per_call(f, calls):
    """Best of 5 runs of `calls` calls, in microseconds per call."""
    best = float("inf")
    for _ in range(5):
        start = time.perf_counter()
        for _ in range(calls):
            f()
        best = min(best, time.perf_counter() - start)
    return best / calls * 1e6


def best_of(f, runs=5):
    best = float("inf")
    for _ in range(runs):
        start = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - start)
    return best


def cpp_figures(model_bench):
    """ns per call of the C++ loops from model_bench: {(name, joints): ns}, 6 the Puma, 7 the WAM."""
    if not model_bench or not Path(model_bench).exists():
        return {}
    out = subprocess.run([model_bench, "--benchmark_filter=(ForwardKinematics|Jacobian|InverseDynamics)_rp/(6|7)$",
                          "--benchmark_format=json", "--benchmark_min_time=0.2"], capture_output=True, text=True,
                         check=True)
    figures = {}
    for b in json.loads(out.stdout)["benchmarks"]:
        name, joints = b["name"].split("_rp/")
        figures[(name, int(joints))] = b["real_time"]
    return figures


def bench_arm(title, model, rows, cpp):
    n = model.dof
    chain = kdl_reference.chain(model)
    rng = np.random.default_rng(0)
    q = rng.uniform(-1, 1, n)
    Q = rng.uniform(-1, 1, (rows, n))
    jq = K.JntArray(n)
    for i in range(n):
        jq[i] = q[i]
    fk_solver, jac_solver = K.ChainFkSolverPos_recursive(chain), K.ChainJntToJacSolver(chain)
    id_solver = K.ChainIdSolver_RNE(chain, K.Vector(*model.gravity))
    frame, jac, tau = K.Frame(), K.Jacobian(n), K.JntArray(n)
    wrenches = [K.Wrench() for _ in range(chain.getNrOfSegments())]

    # The batched calls twice: each making its result array (a large one in a buffer the module
    # kept from the result before, see python/src/ResultBuffers.hpp), and writing into an array
    # made once (out=), as a loop over many batches would.
    fk_out, jac_out, tau_out = np.empty((rows, 4, 4)), np.empty((rows, 6, n)), np.empty((rows, n))
    table = [
        ("ForwardKinematics", lambda: model.fk(q), lambda: fk_solver.JntToCart(jq, frame), lambda: model.fk_batch(Q),
         lambda: model.fk_batch(Q, out=fk_out)),
        ("Jacobian", lambda: model.jacobian(q), lambda: jac_solver.JntToJac(jq, jac), lambda: model.jacobian_batch(Q),
         lambda: model.jacobian_batch(Q, out=jac_out)),
        ("InverseDynamics", lambda: model.rnea(q, q, q), lambda: id_solver.CartToJnt(jq, jq, jq, wrenches, tau),
         lambda: model.rnea_batch(Q, Q, Q), lambda: model.rnea_batch(Q, Q, Q, out=tau_out)),
    ]
    print(f"{title:<18} {'rp single':>10} {'PyKDL':>10} {'rp batched':>11} {'batched out=':>13} {'C++ loop':>9}"
          "   (us per call / row)")
    for name, single, kdl, batched, batched_out in table:
        t_single, t_kdl = per_call(single, 20000), per_call(kdl, 20000)
        t_batch = best_of(batched) / rows * 1e6
        t_out = best_of(batched_out) / rows * 1e6
        t_cpp = cpp.get((name, n), float("nan")) / 1000
        print(f"{name:<18} {t_single:>10.3f} {t_kdl:>10.3f} {t_batch:>11.3f} {t_out:>13.3f} {t_cpp:>9.3f}"
              f"   batched/C++ {t_batch / t_cpp:.2f}, out=/C++ {t_out / t_cpp:.2f}")

    # Two threads, each a batched RNEA over all rows, against the two in sequence.
    sequential = best_of(lambda: (model.rnea_batch(Q, Q, Q), model.rnea_batch(Q, Q, Q)), 3)

    def two_threads():
        threads = [threading.Thread(target=model.rnea_batch, args=(Q, Q, Q)) for _ in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()

    parallel = best_of(two_threads, 3)
    print(f"{title}: rnea_batch x2: sequential {sequential * 1e3:.1f} ms, two Python threads {parallel * 1e3:.1f} ms "
          f"(ratio {parallel / sequential:.2f})")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--model-bench", default=str(Path(__file__).resolve().parents[1] / "build" / "bin" / "model_bench"))
    parser.add_argument("--rows", type=int, default=100000)
    args = parser.parse_args()
    cpp = cpp_figures(args.model_bench)
    bench_arm("Puma 560", rp.Puma560Model(), args.rows, cpp)
    print()
    bench_arm("WAM 7", rp.WAMModel(7), args.rows, cpp)


if __name__ == "__main__":
    main()
