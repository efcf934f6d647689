"""Speed of the generated C (issue 27; run by hand: ``python benchmarks/bench_c.py``).

Exports ``tpm_2ppa.c`` for the paper's prototype, compiles a timing loop with the tests' strict flags
(``cc -std=c99 -O2 ...``) and times 10^6 calls of ``tpm_inverse_dynamics`` on 1024 varied regular states, each call
timed on its own with ``CLOCK_MONOTONIC`` (the clock's own cost, timed the same way, is printed beside it), and the
same 10^6 calls back to back (throughput). Prints the median and p99 per call against the 1 µs target, and the
Python single-state ``inverse_dynamics`` measured in the same run.

Then the page calculator (issue 39) in Node.js (the V8 of Chromium; skipped without ``node``): the shipped
``tpm_2ppa.wasm`` called directly (``tpm_wasm_evaluate``: inverse kinematics, Jacobian, panel quantities and inverse
dynamics of one state) and through ``window.tpm.inverseDynamics`` (the script's checks of the parameters and inputs,
the app's pose rules, its words on a refusal), 21 batches of 20,000 calls on 1024 varied regular states each: the
median and p95 of the per-call time over the batches.
"""

from __future__ import annotations

import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from timing import median_seconds, p95, report

import tpm_viz as tv
from tests.support import cbuild
from tpm_viz.exchange.c.calculator import calculator_assets
from tpm_viz.exchange.c.wasm import shipped

LOOP = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <time.h>
#include "tpm_2ppa.h"
#define N 1000000L
#define STATES 1024
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}
int main(void) {
    const tpm_params prm = TPM_PARAMS_EXPORTED;
    static double p[STATES][2], dp[STATES][2], ddp[STATES][2], call[N], clock_only[N];
    volatile double sink = 0.0;
    double tau[2], t0, total;
    long k;
    for (k = 0; k < STATES; ++k) {
        p[k][0] = 0.1 * sin(0.37 * k); p[k][1] = 0.1 * cos(0.53 * k);
        dp[k][0] = sin(1.1 * k); dp[k][1] = cos(0.7 * k); ddp[k][0] = 10 * sin(0.3 * k); ddp[k][1] = 10 * cos(0.9 * k);
    }
    for (k = 0; k < N; ++k) {
        double a = now(), b;
        if (tpm_inverse_dynamics(&prm, p[k % STATES], dp[k % STATES], ddp[k % STATES], NULL, tau) != 0) return 1;
        b = now();
        sink += tau[0];
        call[k] = b - a;
        a = now();
        b = now();
        clock_only[k] = b - a;
    }
    t0 = now();
    for (k = 0; k < N; ++k) {
        tpm_inverse_dynamics(&prm, p[k % STATES], dp[k % STATES], ddp[k % STATES], NULL, tau);
        sink += tau[1];
    }
    total = now() - t0;
    qsort(call, N, sizeof(double), cmp);
    qsort(clock_only, N, sizeof(double), cmp);
    printf("%.6e %.6e %.6e %.6e %.6e\n", call[N / 2], call[N * 99 / 100], clock_only[N / 2], clock_only[N * 99 / 100],
           total / N);
    return sink == 12345.0;
}
"""


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        directory = cbuild.export(pathlib.Path(tmp))
        (directory / "bench.c").write_text(LOOP)
        exe = cbuild.compile_c([directory / "bench.c", directory / "tpm_2ppa.c"], directory / "bench", directory, [])
        out = subprocess.run([str(exe)], capture_output=True, text=True, check=True, timeout=600).stdout.split()
    med, p99, clock_med, clock_p99, mean = map(float, out)
    print("tpm_inverse_dynamics (C, -O2), 10^6 calls each timed on its own (target <= 1 µs):")
    print(f"  per call: median {med * 1e6:.3f} µs, p99 {p99 * 1e6:.3f} µs (ratio to target {p99 / 1e-6:.2f} at p99)")
    print(f"  the clock alone, included above: median {clock_med * 1e6:.3f} µs, p99 {clock_p99 * 1e6:.3f} µs")
    print(f"  10^6 calls back to back: {mean * 1e6:.3f} µs per call")
    params = tv.Params.paper()
    one = ([0.01, 0.02], [0.3, -0.2], [2.0, 1.0])
    py = median_seconds(lambda: tv.inverse_dynamics(params, *one), repeat=21, inner=2000)
    report("inverse_dynamics (Python), one state", py, None, "µs", 1e6)
    print(f"Python / C (medians): {py / med:.0f} x")
    bench_wasm()


NODE_BENCH = r"""
const STATES = 1024, CALLS = 20000, BATCHES = 21;
const states = [];
for (let k = 0; k < STATES; k++) {
  states.push([[0.1 * Math.sin(0.37 * k), 0.1 * Math.cos(0.53 * k)], [Math.sin(1.1 * k), Math.cos(0.7 * k)],
               [10 * Math.sin(0.3 * k), 10 * Math.cos(0.9 * k)]]);
}
function batches(call) {
  const out = [];
  for (let b = 0; b < BATCHES + 1; b++) {
    const t0 = process.hrtime.bigint();
    for (let k = 0; k < CALLS; k++) call(states[k % STATES]);
    if (b > 0) out.push(Number(process.hrtime.bigint() - t0) * 1e-9 / CALLS);  // the first batch warms up
  }
  return out;
}
tpmReady.then((tpm) => {
  const prm = tpm.defaults;
  const exports = globalThis.__tpmExports;
  const io = new Float64Array(exports.memory.buffer, exports.tpm_wasm_buffer(), exports.tpm_wasm_layout() & 0xff);
  const direct = batches(([p, dp, ddp]) => {
    io.set([prm.a, prm.b, prm.l_a, prm.m_a, prm.m_b, prm.m_p, prm.stroke, 0.03, 0.03, ...p, ...dp, ...ddp], 0);
    if (exports.tpm_wasm_evaluate() !== 0) throw new Error("refused");
  });
  const api = batches(([p, dp, ddp]) => {
    if (!tpm.inverseDynamics({}, p, dp, ddp).tau) throw new Error("refused");
  });
  console.log(JSON.stringify({direct, api}));
});
"""


def bench_wasm() -> None:
    node = shutil.which("node")
    if node is None:
        print("the page calculator: skipped (node is not installed)")
        return
    assets = calculator_assets()
    expose = "const __instantiate = WebAssembly.instantiate;\nWebAssembly.instantiate = async (...a) => {\n"
    expose += "  const r = await __instantiate(...a); globalThis.__tpmExports = r.instance.exports; return r; };\n"
    script = f"globalThis.TPM_WASM_BASE64 = {json.dumps(assets.wasm_b64)};\n{expose}{assets.js}\n{NODE_BENCH}"
    with tempfile.TemporaryDirectory() as tmp:
        path = pathlib.Path(tmp) / "bench.js"
        path.write_text(script)
        out = json.loads(subprocess.run([node, str(path)], capture_output=True, text=True, check=True).stdout)
    version = subprocess.run([node, "--version"], capture_output=True, text=True, check=True).stdout.strip()
    print(f"the page calculator in Node.js {version}, {len(shipped())} bytes of WebAssembly:")
    for name, label in (("direct", "tpm_wasm_evaluate (the module alone)"), ("api", "window.tpm.inverseDynamics")):
        med, top = sorted(out[name])[len(out[name]) // 2], p95(out[name])
        print(f"  {label:<40} median {med * 1e6:.3f} µs, p95 {top * 1e6:.3f} µs per call")


if __name__ == "__main__":
    main()
