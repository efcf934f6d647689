/* page_calc.js: the calculator panel of the offline lesson page (docs/takehome.md). Six typed fields (p in mm, ṗ in
 * m/s, p̈ in m/s²) read with the app's rules (tpmGrader.readQuantity: tpm_viz.core.numbers.parse_quantity, then the
 * app's bounds on a typed vector), and the numbers of window.tpm.evaluate (the generated C as WebAssembly) written as
 * the app's dashboard writes them (tpm.fixed); a refusal in the app's words, never NaN. With "Follow the player" the
 * fields show the frame that viser's player shows (its time slider, read in the 3D view's document) and the numbers
 * are that frame's exact state, the same as its force arrows.
 *
 *   window.tpmPage.data          the page's data (the JSON island #tpm-page-data)
 *   window.tpmPage.W(t, values)  a template of the page's scripts in the page's language
 *   window.tpmPage.calc          {show(k), compute(), playerTime(), state()}: the panel (tests drive it)
 */
(function () {
  "use strict";
  const DATA = JSON.parse(document.getElementById("tpm-page-data").textContent);
  const page = (window.tpmPage = window.tpmPage || {});
  page.data = DATA;

  function W(template, values) {
    const text = Object.prototype.hasOwnProperty.call(DATA.words, template) ? DATA.words[template] : template;
    return text.replace(/\{([A-Za-z_][A-Za-z0-9_]*)\}/g, (all, name) => (name in values ? String(values[name]) : all));
  }
  page.W = W;

  const FIELDS = {
    p1: { name: "p1", unit: "mm", scale: 1e-3, bound: DATA.limits.p_mm },
    p2: { name: "p2", unit: "mm", scale: 1e-3, bound: DATA.limits.p_mm },
    dp1: { name: "ṗ1", unit: "m/s", scale: 1.0, bound: DATA.limits.dp },
    dp2: { name: "ṗ2", unit: "m/s", scale: 1.0, bound: DATA.limits.dp },
    ddp1: { name: "p̈1", unit: "m/s²", scale: 1.0, bound: DATA.limits.ddp },
    ddp2: { name: "p̈2", unit: "m/s²", scale: 1.0, bound: DATA.limits.ddp },
  };
  const frames = DATA.frames;
  const moving = frames.t.length > 1;
  const panel = document.getElementById("tpm-calculator");
  const follow = document.getElementById("tpm-follow");
  const q = (key) => panel.querySelector('[data-q="' + key + '"]');
  let shownFrame = 0;
  let lastTime = null;

  function compact(x) {
    return window.tpm.fixed(x, ".6g"); // tpm_viz.ui.widgets.typed._compact: six significant digits, never -0
  }

  function read(key) {
    // the SI value of a field (tpm_viz.ui.widgets.typed.Quantity.read), or throws a phrase
    const f = FIELDS[key];
    const value = window.tpmGrader.readQuantity(q(key).value, f.name, f.unit);
    if (!(-f.bound <= value && value <= f.bound)) {
      throw window.tpmGrader.P("{name}: {value}{unit} is out of range; type a value from {lo} to {hi}{unit}", {
        name: f.name, value: compact(value), unit: " " + f.unit, lo: compact(-f.bound), hi: compact(f.bound),
      });
    }
    return value * f.scale;
  }

  function set(key, text) {
    const out = q(key);
    if (out.tagName === "OUTPUT") out.textContent = text;
    else out.value = text;
  }

  function write(result) {
    const tpm = window.tpm;
    const ok = result && !result.error;
    const deg = 180 / Math.PI;
    set("d1", ok ? tpm.fixed(result.d[0] * 1e3, ".1f") : "—");
    set("d2", ok ? tpm.fixed(result.d[1] * 1e3, ".1f") : "—");
    set("theta1", ok ? tpm.fixed(result.theta[0] * deg, ".2f") : "—");
    set("theta2", ok ? tpm.fixed(result.theta[1] * deg, ".2f") : "—");
    set("det_jx", ok ? tpm.fixed(result.detJx, ".4f") : "—");
    set("det_jq", ok ? tpm.fixed(result.detJq, ".4f") : "—");
    set("cond", ok ? tpm.fixed(result.cond, ".2f") : "—");
    set("mode", ok ? (result.mode > 0 ? "+ (det J_x > 0)" : "− (det J_x < 0)") : "—");
    set("tau1", ok ? tpm.fixed(result.tau[0], ".2f") : "—");
    set("tau2", ok ? tpm.fixed(result.tau[1], ".2f") : "—");
    const warnings = [];
    if (ok) {
      for (let i = 0; i < 2; i++) {
        if (result.near.inverse[i]) {
          warnings.push(W("leg {i} is near its inverse singularity (|cos θ{i}| < {limit})", { i: i + 1, limit: tpm.limits.warn_cos }));
        }
      }
      if (result.near.direct) warnings.push(W("near the direct singularity (|det J_x| < {limit})", { limit: tpm.limits.warn_det }));
    }
    document.getElementById("tpm-warning").textContent = warnings.join("; ");
  }

  function refuse(text) {
    document.getElementById("tpm-refusal").textContent = text;
    write(null);
  }

  function evaluate(p, dp, ddp) {
    const result = window.tpm.evaluate(DATA.params, p, dp, ddp, { lang: DATA.lang });
    if (result.error) refuse(result.error);
    else {
      document.getElementById("tpm-refusal").textContent = "";
      write(result);
    }
    return result;
  }

  function compute() {
    // the typed fields -> the numbers (or the first field's refusal)
    const values = {};
    for (const key of Object.keys(FIELDS)) {
      try {
        values[key] = read(key);
      } catch (exc) {
        if (!exc || !exc.template) throw exc;
        refuse(window.tpmGrader.render(exc));
        return null;
      }
    }
    return evaluate([values.p1, values.p2], [values.dp1, values.dp2], [values.ddp1, values.ddp2]);
  }

  function show(k) {
    // frame k of the recording: its state in the fields (as the app shows a number) and its exact numbers
    shownFrame = k;
    const p = frames.p[k];
    const dp = frames.dp[k];
    const ddp = frames.ddp[k];
    const tpm = window.tpm;
    set("p1", compact(p[0] * 1e3));
    set("p2", compact(p[1] * 1e3));
    set("dp1", compact(dp[0]));
    set("dp2", compact(dp[1]));
    set("ddp1", compact(ddp[0]));
    set("ddp2", compact(ddp[1]));
    const time = document.getElementById("tpm-time");
    if (time) {
      const T = frames.t[frames.t.length - 1];
      time.textContent = "(" + W("at t = {t} s of {T} s", { t: tpm.fixed(frames.t[k], ".3f"), T: tpm.fixed(T, ".3f") }) + ")";
    }
    return evaluate(p, dp, ddp);
  }

  function playerTime() {
    // the time [s] of viser's player in the 3D view (its slider), or null (not drawn yet, or not readable)
    try {
      const view = document.getElementById("tpm-view"); // after this script in the page: looked up when asked
      const doc = view && view.contentDocument;
      const slider = doc && doc.querySelector('[role="slider"]');
      if (!slider) return null;
      const t = Number(slider.getAttribute("aria-valuenow"));
      return Number.isFinite(t) ? t : null;
    } catch (err) {
      return null;
    }
  }

  function frameAt(t) {
    // the frame the player shows at time t: the last one at or before t
    let k = 0;
    while (k + 1 < frames.t.length && frames.t[k + 1] <= t + 1e-9) k++;
    return k;
  }

  function tick() {
    const t = playerTime();
    if (t === null || t === lastTime) return;
    lastTime = t;
    if (follow && follow.checked) {
      const k = frameAt(t);
      if (k !== shownFrame) show(k);
    }
  }

  page.calc = {
    show,
    compute,
    playerTime,
    frameAt,
    state: () => ({ frame: shownFrame, follow: follow ? follow.checked : false }),
  };

  window.tpmReady.then(function () {
    show(0);
    for (const key of Object.keys(FIELDS)) {
      // a field in the student's hands leaves the player at once: the player never writes under their cursor
      q(key).addEventListener("focus", function () {
        if (follow) follow.checked = false;
      });
      q(key).addEventListener("input", function () {
        if (follow) follow.checked = false;
        compute();
      });
    }
    if (follow) {
      follow.addEventListener("change", function () {
        if (follow.checked) show(lastTime === null ? shownFrame : frameAt(lastTime));
      });
    }
    if (moving) setInterval(tick, 100);
    page.calcReady = true;
    window.dispatchEvent(new Event("tpm-page-calc"));
  });
})();
