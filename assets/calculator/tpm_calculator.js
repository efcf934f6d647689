/* tpm_calculator.js: the 2-PPa TPM's closed form in a page, as window.tpm (docs/realtime.md, "The calculator in a
 * page"). The numbers come from the generated C compiled to WebAssembly (tpm_2ppa.wasm, inlined in the page as base64
 * in <script id="tpm-wasm" type="application/wasm;base64">); this script only checks the inputs, refuses what the app
 * refuses, in the app's words (English or Korean), and copies numbers out. SI units: metres, m/s, m/s^2, newtons.
 *
 *   window.tpmReady                                      a Promise of window.tpm (also the event "tpm-ready")
 *   tpm.inverseKinematics(params, p, options)            {d: [d1, d2]} or {error: "..."}
 *   tpm.inverseDynamics(params, p, dp, ddp, options)     {tau: [tau1, tau2]} or {error: "..."}
 *   tpm.evaluate(params, p, dp, ddp, options)            the panel at a pose: {d, theta, detJx, detJq, cond, tau,
 *                                                        mode, near: {inverse: [b1, b2], direct: b}} or {error}
 *   params: {a, b, l_a, m_a, m_b, m_p, stroke, pivot_spacing} (missing keys: the paper's values); p, dp, ddp: [x, y];
 *   options: {lang: "en" | "ko"} (default tpm.lang, "en"). Every number returned is finite.
 *   tpm.fixed(x, spec)                                   x as the app shows numbers (".1f", ".3f", ".6g": Python's
 *                                                        format, a dash for what is not finite, no negative zero)
 *
 * The refusals, in the order they are checked: parameters by the rules of tpm_viz/core/params.py ("parameters refused:
 * ..."); p, dp, ddp by the app's typed-load rules (two numbers, finite); then the pose as the app places a
 * trajectory sample (tpm_viz.app.moves.place): unreachable, an actuator outside 0 <= d_i <= stroke, a leg within the
 * app's move limit of its inverse singularity (|cos th_i| < 0.03, eq. 11), the legs within it of the direct one
 * (|cos(th1 + th2)| < 0.03, eq. 12); last, a force that overflows. The configuration (the paper's parameters, the
 * limits, the Korean words) is written in by tpm_viz.exchange.c.calculator.calculator_assets().
 */
(function (root) {
  "use strict";
  const CONFIG = /*@tpm-config@*/ null;
  if (CONFIG === null) {
    throw new Error("tpm_calculator.js needs its configuration: take it from tpm_viz.exchange.calculator_assets()");
  }
  const FIELDS = ["a", "b", "l_a", "m_a", "m_b", "m_p", "stroke", "pivot_spacing"];
  const LENGTH = { unit: "mm", scale: 1e3, si: "m" };
  const MASS = { unit: "kg", scale: 1.0, si: "kg" };
  const UNITS = { a: LENGTH, b: LENGTH, l_a: LENGTH, m_a: MASS, m_b: MASS, m_p: MASS, stroke: LENGTH };
  UNITS.pivot_spacing = LENGTH;
  const RANGES = { m: [1e-6, 100.0], kg: [1e-9, 1e4] }; // as tpm_viz.core.params (every derived quantity finite)
  const STROKE_TOL = 1e-9; // [m], as tpm_viz.app.moves: an actuator this far past an end is still inside
  const DASH = "\u2014";

  // ------------------------------------------------------------------ numbers written as Python writes them
  function exact(x) {
    // |x| (finite) as n / 10^scale exactly, n a BigInt
    const view = new DataView(new ArrayBuffer(8));
    view.setFloat64(0, Math.abs(x));
    const hi = view.getUint32(0);
    const lo = view.getUint32(4);
    const biased = (hi >>> 20) & 0x7ff;
    let mant = (BigInt(hi & 0xfffff) << 32n) | BigInt(lo);
    let e = -1074;
    if (biased !== 0) {
      mant |= 1n << 52n;
      e = biased - 1075;
    }
    if (e >= 0) return { n: mant << BigInt(e), scale: 0 };
    return { n: mant * 5n ** BigInt(-e), scale: -e };
  }

  function rounded(v, decimals) {
    // v = {n, scale} rounded half to even at `decimals` digits after the point (negative: before): q / 10^decimals
    if (decimals >= v.scale) return v.n * 10n ** BigInt(decimals - v.scale);
    const div = 10n ** BigInt(v.scale - decimals);
    let q = v.n / div;
    const twice = 2n * (v.n % div);
    if (twice > div || (twice === div && (q & 1n) === 1n)) q += 1n;
    return q;
  }

  function pointed(q, decimals) {
    // the digits of q / 10^decimals with a point
    if (decimals <= 0) return q.toString() + "0".repeat(-decimals);
    const s = q.toString().padStart(decimals + 1, "0");
    return s.slice(0, s.length - decimals) + "." + s.slice(s.length - decimals);
  }

  function formatF(x, decimals) {
    // format(x, ".Nf")
    if (Number.isNaN(x)) return "nan";
    if (!Number.isFinite(x)) return x > 0 ? "inf" : "-inf";
    const text = pointed(rounded(exact(x), decimals), decimals);
    return (x < 0 || Object.is(x, -0) ? "-" : "") + text;
  }

  function formatG(x, precision) {
    // format(x, ".Pg") (and "g": precision 6)
    if (Number.isNaN(x)) return "nan";
    if (!Number.isFinite(x)) return x > 0 ? "inf" : "-inf";
    const sign = x < 0 || Object.is(x, -0) ? "-" : "";
    if (x === 0) return sign + "0";
    const v = exact(x);
    let exp = v.n.toString().length - 1 - v.scale; // decimal exponent of |x|
    let q = rounded(v, precision - 1 - exp);
    if (q.toString().length > precision) {
      exp += 1;
      q /= 10n;
    }
    const digits = q.toString();
    if (exp >= -4 && exp < precision) {
      let text = pointed(q, precision - 1 - exp);
      if (text.includes(".")) text = text.replace(/0+$/, "").replace(/\.$/, "");
      return sign + text;
    }
    let mantissa = digits[0] + (digits.length > 1 ? "." + digits.slice(1) : "");
    if (mantissa.includes(".")) mantissa = mantissa.replace(/0+$/, "").replace(/\.$/, "");
    const e = Math.abs(exp).toString().padStart(2, "0");
    return sign + mantissa + "e" + (exp < 0 ? "-" : "+") + e;
  }

  function fixed(x, spec) {
    // tpm_viz.core.numbers.fixed: a dash for what is not finite, never a negative zero
    if (typeof x !== "number" || !Number.isFinite(x)) return DASH;
    const text = spec.endsWith("g") ? formatG(x, Number(spec.slice(1, -1))) : formatF(x, Number(spec.slice(1, -1)));
    const mantissa = text.split(/[eE]/)[0];
    if (mantissa.includes("-") && !/[1-9]/.test(mantissa)) return fixed(0, spec);
    return text;
  }

  function pyRepr(value) {
    // what Python's repr() shows for the value a page passed (strings quoted as Python quotes them)
    if (value === null || value === undefined) return "None";
    if (typeof value === "boolean") return value ? "True" : "False";
    if (typeof value === "number") {
      if (Number.isNaN(value)) return "nan";
      if (!Number.isFinite(value)) return value > 0 ? "inf" : "-inf";
      return Number.isInteger(value) && Math.abs(value) < 1e16 ? String(value) : formatG(value, 17);
    }
    if (typeof value === "string") {
      const quote = value.includes("'") && !value.includes('"') ? '"' : "'";
      const body = value.replace(/\\/g, "\\\\").replace(/\n/g, "\\n").replace(/\r/g, "\\r").replace(/\t/g, "\\t");
      return quote + (quote === "'" ? body.replace(/'/g, "\\'") : body) + quote;
    }
    if (Array.isArray(value)) return "[" + value.map(pyRepr).join(", ") + "]";
    if (typeof value === "bigint") return value.toString();
    if (typeof value === "object") {
      try {
        return JSON.stringify(value).slice(0, 200);
      } catch (err) {
        return "<object>";
      }
    }
    return String(value);
  }

  // ------------------------------------------------------------------ words (tpm_viz.core.words.Phrase, str.format)
  function P(template, values) {
    return { template: template, values: values || {} };
  }

  function fill(text, values, lang) {
    return text.replace(/\{([A-Za-z_][A-Za-z0-9_]*)(?::([^{}]*))?\}/g, function (all, name, spec) {
      if (!(name in values)) throw new Error("missing field " + name);
      const value = values[name];
      if (value && typeof value === "object" && "template" in value) return render(value, lang);
      if (spec === "g") return formatG(value, 6);
      if (spec) return fixed(value, spec);
      return String(value);
    });
  }

  function render(phrase, lang) {
    const template = lang === "ko" && CONFIG.ko[phrase.template] ? CONFIG.ko[phrase.template] : phrase.template;
    try {
      return fill(template, phrase.values, lang);
    } catch (err) {
      return fill(phrase.template, phrase.values, lang); // a broken translation falls back to the English
    }
  }

  function language(options) {
    const given = (options && options.lang) || api.lang || "en";
    const tag = String(given).trim().toLowerCase();
    return tag === "한국어" || tag.split("-")[0] === "ko" ? "ko" : "en";
  }

  // ------------------------------------------------------------------ parameters: tpm_viz/core/params.py's rules
  function ui(name, value) {
    return fixed(value * UNITS[name].scale, ".6g");
  }

  const SQRT2 = Math.sqrt(2.0);
  function beyondReach(v) {
    return v.a - v.b - SQRT2 * v.l_a >= v.stroke;
  }
  function behindStart(v) {
    return v.a - v.b + v.l_a <= 0.0;
  }
  const FIXES = {
    beyond: {
      l_a: [true, (v) => (v.a - v.b - v.stroke) / SQRT2],
      stroke: [true, (v) => v.a - v.b - SQRT2 * v.l_a],
      a: [false, (v) => v.b + v.stroke + SQRT2 * v.l_a],
      b: [true, (v) => v.a - v.stroke - SQRT2 * v.l_a],
    },
    behind: {
      l_a: [true, (v) => v.b - v.a],
      a: [true, (v) => v.b - v.l_a],
      b: [false, (v) => v.a + v.l_a],
    },
  };
  const RULES = { beyond: beyondReach, behind: behindStart };

  function fits(v, spacing) {
    return !(beyondReach(v) || behindStart(v)) && spacing < v.l_a;
  }

  function shownBound(rule, name, v, spacing) {
    const [lower, bound] = FIXES[rule][name];
    let edge = bound(v);
    if (name === "l_a") edge = Math.max(edge, spacing);
    let k = lower ? Math.floor(edge * 1e4) : Math.ceil(edge * 1e4);
    for (let step = 0; step < 100; step++) {
      if (k > 0 && fits(Object.assign({}, v, { [name]: (k / 10) * 1e-3 }), spacing)) return fixed(k / 10, ".1f");
      k += lower ? 1 : -1;
    }
    return null;
  }

  function fixOf(rule, name, bound, v) {
    const mm = { a: ui("a", v.a), b: ui("b", v.b), l_a: ui("l_a", v.l_a), stroke: ui("stroke", v.stroke) };
    const { a, b, l_a, stroke } = mm;
    if (rule === "beyond") {
      if (name === "l_a") {
        return P("l_a must be at least {bound} mm with a = {a} mm, b = {b} mm and the stroke Δd = {stroke} mm", {
          bound, a, b, stroke,
        });
      }
      if (name === "stroke") {
        return P("the stroke Δd must be at least {bound} mm with a = {a} mm, b = {b} mm and l_a = {l_a} mm", {
          bound, a, b, l_a,
        });
      }
      if (name === "a") {
        return P("a must be at most {bound} mm with b = {b} mm, l_a = {l_a} mm and the stroke Δd = {stroke} mm", {
          bound, b, l_a, stroke,
        });
      }
      return P("b must be at least {bound} mm with a = {a} mm, l_a = {l_a} mm and the stroke Δd = {stroke} mm", {
        bound, a, l_a, stroke,
      });
    }
    if (name === "l_a") return P("l_a must be at least {bound} mm with a = {a} mm and b = {b} mm", { bound, a, b });
    if (name === "a") return P("a must be at least {bound} mm with b = {b} mm and l_a = {l_a} mm", { bound, b, l_a });
    return P("b must be at most {bound} mm with a = {a} mm and l_a = {l_a} mm", { bound, a, l_a });
  }

  function alternativeOf(rule, name, bound) {
    const lower = FIXES[rule][name][0];
    if (name === "l_a") return P("or l_a at least {bound} mm", { bound });
    if (name === "stroke") return P("or the stroke Δd at least {bound} mm", { bound });
    if (name === "a") return lower ? P("or a at least {bound} mm", { bound }) : P("or a at most {bound} mm", { bound });
    return lower ? P("or b at least {bound} mm", { bound }) : P("or b at most {bound} mm", { bound });
  }

  function geometryProblem(v, spacing, prefer) {
    for (const rule of ["beyond", "behind"]) {
      if (!RULES[rule](v)) continue;
      const names = [];
      for (const n of [...prefer, "l_a", "stroke", "a", "b"]) {
        if (n in FIXES[rule] && !names.includes(n)) names.push(n);
      }
      const usable = [];
      for (const n of names) {
        const bound = shownBound(rule, n, v, spacing);
        if (bound !== null) usable.push([n, bound]);
      }
      let fix = usable.length
        ? fixOf(rule, usable[0][0], usable[0][1], v)
        : P("change a, b, l_a, the stroke Δd or the pivot spacing");
      if (usable.length > 1) {
        fix = P("{fix} ({alternative})", { fix, alternative: alternativeOf(rule, usable[1][0], usable[1][1]) });
      }
      if (rule === "beyond") {
        return P(
          "{fix}: otherwise there is no reachable pose inside the stroke, the sliders would have to go beyond " +
            "d = Δd (the rule is a − b − √2 l_a < Δd)",
          { fix },
        );
      }
      return P(
        "{fix}: otherwise there is no reachable pose inside the stroke, the sliders would have to go behind " +
          "d = 0 (the rule is a − b + l_a > 0)",
        { fix },
      );
    }
    return null;
  }

  function fieldProblem(name, value) {
    const unit = UNITS[name];
    if (typeof value !== "number") {
      return P("parameter {name} must be a number, got {got}", { name, got: pyRepr(value) });
    }
    if (!Number.isFinite(value)) {
      return P("parameter {name} must be a finite number of {unit}, got {got}", {
        name, unit: unit.unit, got: pyRepr(value),
      });
    }
    if (value <= 0.0) {
      return unit === LENGTH
        ? P("parameter {name} must be positive, got {value} mm: it is a length, more than 0 mm", {
            name, value: ui(name, value),
          })
        : P("parameter {name} must be positive, got {value} kg: it is a mass, more than 0 kg", {
            name, value: ui(name, value),
          });
    }
    const [low, high] = RANGES[unit.si];
    if (!(low <= value && value <= high)) {
      return P(
        "parameter {name} must be between {low} and {high} {unit}, got {value} {unit}: beyond that range the " +
          "computations lose their precision",
        { name, low: ui(name, low), high: ui(name, high), value: ui(name, value), unit: unit.unit },
      );
    }
    return null;
  }

  function parameters(given) {
    // {params} or {why}: Params.paper().replace(**given), as the app builds a parameter set
    if (given === undefined) return { params: Object.assign({}, CONFIG.defaults) };
    if (given === null || typeof given !== "object" || Array.isArray(given)) {
      const got = pyRepr(given);
      return { why: P("the parameters must be an object of named numbers (SI units), got {got}", { got }) };
    }
    const changes = {};
    for (const key of Object.keys(given)) {
      if (given[key] !== undefined) changes[key] = given[key];
    }
    const unknown = Object.keys(changes).filter((k) => !FIELDS.includes(k)).sort();
    if (unknown.length) {
      const name = pyRepr(unknown[0]);
      return { why: P("unknown parameter {name}; known: {known}", { name, known: FIELDS.join(", ") }) };
    }
    const v = Object.assign({}, CONFIG.defaults, changes);
    for (const name of FIELDS) {
      const why = fieldProblem(name, v[name]);
      if (why) return { why };
    }
    const lengths = { a: v.a, b: v.b, l_a: v.l_a, stroke: v.stroke };
    if (geometryProblem(lengths, v.pivot_spacing, []) !== null) {
      const changed = ["a", "b", "l_a", "stroke"].filter((n) => lengths[n] !== CONFIG.defaults[n]);
      return { why: geometryProblem(lengths, v.pivot_spacing, changed) };
    }
    if (v.pivot_spacing >= v.l_a) {
      return {
        why: P(
          "the pivot spacing must be less than the link length l_a = {l_a} mm, got {spacing} mm (or l_a more than " +
            "{spacing} mm): the two links of a parallelogram are drawn that far apart",
          { l_a: ui("l_a", v.l_a), spacing: ui("pivot_spacing", v.pivot_spacing) },
        ),
      };
    }
    return { params: v };
  }

  function vector(value, name) {
    // {xy} or {why}: the app's rules for a typed pair (tpm_viz.app.readouts.Load)
    const ok = (Array.isArray(value) || ArrayBuffer.isView(value)) && value.length === 2;
    if (!ok || typeof value[0] !== "number" || typeof value[1] !== "number") {
      return { why: P("{name} must be two numbers, got {got}", { name, got: pyRepr(value) }) };
    }
    const x = value[0];
    const y = value[1];
    if (!(Number.isFinite(x) && Number.isFinite(y))) {
      return { why: P("{name} must be finite, got ({x:g}, {y:g})", { name, x, y }) };
    }
    return { xy: [x, y] };
  }

  // ------------------------------------------------------------------ the module
  let wasm = null; // {evaluate, io, out}

  function compute(prm, p, dp, ddp) {
    const io = wasm.io;
    const fields = [prm.a, prm.b, prm.l_a, prm.m_a, prm.m_b, prm.m_p, prm.stroke];
    fields.push(CONFIG.limits.min_cos, CONFIG.limits.min_det, p[0], p[1], dp[0], dp[1], ddp[0], ddp[1]);
    io.set(fields, 0);
    wasm.evaluate();
    const o = (k) => io[wasm.out + k];
    return {
      rcTau: o(2),
      d: [o(3), o(4)],
      cos: [o(5), o(6)],
      sin: [o(7), o(8)],
      theta: [o(9), o(10)],
      detJx: o(11),
      detJq: o(12),
      mode: o(13),
      rcJ: o(1),
      cond: o(18),
      tau: [o(19), o(20)],
    };
  }

  // ------------------------------------------------------------------ the app's refusal of a pose (moves.place)
  const STROKE = 3;
  const NEAR_INVERSE = 1;
  const NEAR_DIRECT = 2;

  function poseCode(prm, p, r) {
    // tpm_viz.app.moves.pose_codes: the first failing rule of the stroke, inverse, direct columns
    const m = [
      Math.min(r.d[0], prm.stroke - r.d[0]) + STROKE_TOL,
      Math.min(r.d[1], prm.stroke - r.d[1]) + STROKE_TOL,
      Math.abs(r.cos[0]) - CONFIG.limits.min_cos,
      Math.abs(r.cos[1]) - CONFIG.limits.min_cos,
      r.mode * r.detJx - CONFIG.limits.min_det,
    ];
    const codes = [STROKE, STROKE, NEAR_INVERSE, NEAR_INVERSE, NEAR_DIRECT];
    for (let k = 0; k < 5; k++) {
      // the pose's own branch (c_i >= 0: +1) against the sign of c_i: they differ only where c_i = 0
      const wrongBranch = (k === 2 || k === 3) && Math.sign(r.cos[k - 2]) !== (r.cos[k - 2] >= 0 ? 1 : -1);
      if (m[k] < 0.0 || wrongBranch) return codes[k];
    }
    return 0;
  }

  function whyNot(prm, code, p, r) {
    // tpm_viz.app.moves.why_not for a placed pose (cause "path")
    if (code === STROKE) {
      const over = [Math.max(-r.d[0], r.d[0] - prm.stroke), Math.max(-r.d[1], r.d[1] - prm.stroke)];
      const i = over[1] > over[0] ? 1 : 0;
      return P(
        "actuator {i} would leave its stroke: slider {i} would have to be at d{i} = {d} mm, beyond its end-stops " +
          "at 0 and {stroke} mm",
        { i: i + 1, d: fixed(r.d[i] * 1e3, ".1f"), stroke: fixed(prm.stroke * 1e3, ".0f") },
      );
    }
    if (code === NEAR_INVERSE) {
      const i = Math.abs(r.cos[1]) < Math.abs(r.cos[0]) ? 1 : 0;
      return P(
        "leg {i} would come too close to an inverse singularity: its links would stand almost perpendicular to " +
          "rail {i}, where actuator {i} loses its authority along them ({value}eq. 11)",
        { i: i + 1, value: "cos θ" + (i + 1) + " = " + fixed(r.cos[i], ".3f") + ", " },
      );
    }
    const det = r.cos[0] * r.cos[1] - (p[1] * p[0]) / (prm.l_a * prm.l_a);
    const dot = r.cos[0] * p[1] + p[0] * r.cos[1];
    const kind = dot > 0 ? P("the leg circles coincide") : P("the two assembly modes merge");
    return P(
      "the platform would come too close to the direct singularity, where it gains a degree of freedom: it " +
        "loses its stiffness in one direction and the actuator forces grow without bound for a load along it; " +
        "{kind} ({value}eq. 12)",
      { kind, value: "cos(θ1+θ2) = " + fixed(det, ".3f") + ", " },
    );
  }

  function refused(why) {
    return P("refused: {why}", { why });
  }

  function state(params, p, dp, ddp) {
    // {prm, p, r} or {why}: every check up to the pose, then the module's numbers
    const given = parameters(params);
    if (given.why) return { why: P("parameters refused: {why}", { why: given.why }) };
    const inputs = [vector(p, "p")];
    if (dp !== null) inputs.push(vector(dp, "dp"), vector(ddp, "ddp"));
    for (const input of inputs) if (input.why) return { why: input.why };
    const prm = given.params;
    const xy = inputs.map((input) => input.xy);
    const zero = [0.0, 0.0];
    const r = compute(prm, xy[0], xy[1] || zero, xy[2] || zero);
    if (!(Number.isFinite(r.d[0]) && Number.isFinite(r.d[1]))) {
      return {
        why: refused(
          P(
            "out of reach: a leg of length l_a = {l_a} mm cannot reach the platform there (|p1| and |p2| must " +
              "stay below l_a)",
            { l_a: fixed(prm.l_a * 1e3, ".1f") },
          ),
        ),
      };
    }
    const code = poseCode(prm, xy[0], r);
    if (code) return { why: refused(whyNot(prm, code, xy[0], r)) };
    return { prm, p: xy[0], r };
  }

  function forces(s) {
    // {tau} or {why}: the generated tpm_inverse_dynamics' result or refusal, in the library's words
    const rc = s.r.rcTau;
    if (rc === 0 && Number.isFinite(s.r.tau[0]) && Number.isFinite(s.r.tau[1])) return { tau: s.r.tau };
    if (rc === 3 || rc === 4) return { why: refused(whyNot(s.prm, rc === 3 ? NEAR_INVERSE : NEAR_DIRECT, s.p, s.r)) };
    if (rc === 6) {
      return {
        why: P("{what} overflowed: the inputs are too large for finite results", { what: P("the actuator forces") }),
      };
    }
    return { why: P("the calculator refused this state (code {code})", { code: rc }) };
  }

  function finiteAll(values) {
    return values.every((x) => x === null || Number.isFinite(x));
  }

  const api = {
    lang: "en",
    fixed: fixed, // a number as the app shows it (tpm_viz.core.numbers.fixed): ".1f", ".3f", ".6g"; a dash if not finite
    defaults: Object.freeze(Object.assign({}, CONFIG.defaults)),
    limits: Object.freeze(Object.assign({ stroke_tol: STROKE_TOL }, CONFIG.limits)),
    inverseKinematics(params, p, options) {
      const lang = language(options);
      const s = state(params, p, null, null);
      if (s.why) return { error: render(s.why, lang) };
      return { d: s.r.d.slice() };
    },
    inverseDynamics(params, p, dp, ddp, options) {
      const lang = language(options);
      const s = state(params, p, dp, ddp);
      if (s.why) return { error: render(s.why, lang) };
      const f = forces(s);
      return f.why ? { error: render(f.why, lang) } : { tau: f.tau.slice() };
    },
    evaluate(params, p, dp, ddp, options) {
      const lang = language(options);
      const s = state(params, p, dp === undefined ? [0.0, 0.0] : dp, ddp === undefined ? [0.0, 0.0] : ddp);
      if (s.why) return { error: render(s.why, lang) };
      const f = forces(s);
      if (f.why) return { error: render(f.why, lang) };
      const r = s.r;
      const cond = r.rcJ === 0 && Number.isFinite(r.cond) ? r.cond : null;
      const out = {
        d: r.d.slice(),
        theta: r.theta.slice(),
        detJx: r.detJx,
        detJq: r.detJq,
        cond: cond,
        tau: f.tau.slice(),
        mode: r.mode,
        near: {
          inverse: [Math.abs(r.cos[0]) < CONFIG.limits.warn_cos, Math.abs(r.cos[1]) < CONFIG.limits.warn_cos],
          direct: Math.abs(r.detJx) < CONFIG.limits.warn_det,
        },
      };
      if (!finiteAll([...out.d, ...out.theta, out.detJx, out.detJq, out.cond, ...out.tau])) {
        return { error: render(P("the calculator refused this state (code {code})", { code: -1 }), lang) };
      }
      return out;
    },
  };

  function base64Bytes(text) {
    const raw = atob(text.replace(/\s+/g, ""));
    const bytes = new Uint8Array(raw.length);
    for (let k = 0; k < raw.length; k++) bytes[k] = raw.charCodeAt(k);
    return bytes;
  }

  async function install() {
    const element = root.document && root.document.getElementById("tpm-wasm");
    const text = element ? element.textContent : root.TPM_WASM_BASE64;
    if (!text) throw new Error("tpm_calculator.js: no module (the element #tpm-wasm with tpm_2ppa.wasm as base64)");
    const { instance } = await WebAssembly.instantiate(base64Bytes(text), {});
    const exports = instance.exports;
    const layout = exports.tpm_wasm_layout();
    const size = layout & 0xff;
    wasm = {
      evaluate: exports.tpm_wasm_evaluate,
      io: new Float64Array(exports.memory.buffer, exports.tpm_wasm_buffer(), size),
      out: layout >> 8,
    };
    root.tpm = api;
    if (typeof root.dispatchEvent === "function" && typeof Event === "function") {
      root.dispatchEvent(new Event("tpm-ready"));
    }
    return root.tpm;
  }

  root.tpmReady = install();
})(typeof window !== "undefined" ? window : globalThis);
