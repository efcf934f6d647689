/* page_grader.js: the exercise grader of tpm_viz.app.exercises in an offline lesson page (docs/takehome.md). A port of
 * the rules of docs/exercises.md ("How an answer is read", "How a readable answer is graded") for number, pose and
 * choice answers: tpm_viz.core.numbers.parse_number / parse_quantity (Python's float() grammar, the decimal comma, the
 * Unicode minus, digit groups, units of the answer's quantity), tpm_viz.app.exercises.answers (several numbers, the
 * format errors), tpm_viz.app.exercises.tasks (the pose rules) and tpm_viz.app.exercises.grading (relabs, the
 * mistakes in file order, the attempt ladder, round(score, 9)). Every line a student reads is the app's phrase in the
 * page's language.
 *
 * The page's variant is fixed (its seed), so the page carries what depends only on it, computed by the library when
 * the page was made (tpm_viz.media.page_exercises): a number's reference and the value of every `answer` mistake in
 * the exercise's unit, the mistakes' feedback, the right option of a choice. What depends on the answer is computed
 * here: the reading, the comparisons and, for a pose, the pose rules (eq. 4, 11, 12) and the forces at the typed pose
 * (eqs. 28-31) from window.tpm, the generated C as WebAssembly (tpm_calculator.js).
 *
 *   window.tpmGrader.grade(exercise, text, attempt)  {score, format_error, feedback, attempts_used}: the JSON of
 *                                                     `tpm-viz exercise grade` (score after the ladder; a format
 *                                                     error: score null, attempts_used 0)
 *   window.tpmGrader.readQuantity(text, name, unit)   a typed number in `unit`, or throws a phrase (render it)
 *   window.tpmGrader.render(phrase)                   a phrase {template, values} or {text} in the page's language
 *
 * The configuration (the page's language and Korean templates, Python's whitespace and digit characters, the units)
 * is written in by tpm_viz.media.page_grader.grader_script().
 */
(function (root) {
  "use strict";
  const CONFIG = /*@tpm-grader-config@*/ null;
  if (CONFIG === null) {
    throw new Error("page_grader.js needs its configuration: take it from tpm_viz.media.page_grader.grader_script()");
  }
  const MAX_TEXT = 400; // tpm_viz.core.numbers.MAX_TEXT [characters]
  const QUOTE = 40; // tpm_viz.core.numbers.QUOTE
  const MAX_ANSWER = 200; // tpm_viz.app.exercises.model.MAX_ANSWER
  const STROKE_EDGE = 1e-12; // [m] tpm_viz.app.exercises.tasks.pose_problem: 0 - 1e-12 <= d_i <= stroke + 1e-12

  // ------------------------------------------------------------------ words (tpm_viz.core.words.Phrase)
  function P(template, values) {
    return { template: template, values: values || {} };
  }

  function isPhrase(value) {
    return value !== null && typeof value === "object" && ("template" in value || "text" in value);
  }

  function fill(template, values) {
    return template.replace(/\{([A-Za-z_][A-Za-z0-9_]*)\}/g, function (all, name) {
      if (!(name in values)) throw new Error("missing field " + name);
      const value = values[name];
      return isPhrase(value) ? render(value) : String(value);
    });
  }

  function render(phrase) {
    // the phrase in the page's language (English if the catalogue has no entry or the entry does not fill)
    if (typeof phrase === "string") return phrase;
    if ("text" in phrase) return phrase.text; // a text the library rendered when the page was made
    const ko = CONFIG.lang === "ko" ? CONFIG.ko[phrase.template] : undefined;
    if (ko !== undefined) {
      try {
        return fill(ko, phrase.values);
      } catch (err) {
        /* a broken translation falls back to the English template, as Phrase.render does */
      }
    }
    return fill(phrase.template, phrase.values);
  }

  // ------------------------------------------------------------------ Python's str, as the reader uses it
  const SPACE = new Set(Array.from(CONFIG.spaces)); // str.isspace()
  const DIGITISH = new Set(Array.from(CONFIG.digitish)); // str.isdigit() but not str.isdecimal() (², ³, ...)
  const STARTS = CONFIG.decimal_starts; // first code point (value 0) of every run of ten Unicode decimal digits
  const WS = "[" + Array.from(CONFIG.spaces).map(classChar).join("") + "]"; // Python's \s (str patterns)
  const WS_CHARS = Array.from(CONFIG.spaces).map(classChar).join("");
  const NON_PRINTABLE = /[\p{Cc}\p{Cf}\p{Cs}\p{Co}\p{Cn}\p{Zl}\p{Zp}\p{Zs}]/u; // str.isprintable() is false

  function classChar(ch) {
    return "\\u{" + ch.codePointAt(0).toString(16) + "}";
  }

  function chars(text) {
    return Array.from(text); // code points, as Python counts and slices a str
  }

  function decimalValue(ch) {
    // unicodedata.decimal(ch), or -1
    const cp = ch.codePointAt(0);
    let lo = 0;
    let hi = STARTS.length - 1;
    let found = -1;
    while (lo <= hi) {
      const mid = (lo + hi) >> 1;
      if (STARTS[mid] <= cp) {
        found = mid;
        lo = mid + 1;
      } else {
        hi = mid - 1;
      }
    }
    return found >= 0 && cp - STARTS[found] < 10 ? cp - STARTS[found] : -1;
  }

  function isDigit(ch) {
    return decimalValue(ch) >= 0 || DIGITISH.has(ch);
  }

  function strip(text) {
    const c = chars(text);
    let i = 0;
    let j = c.length;
    while (i < j && SPACE.has(c[i])) i++;
    while (j > i && SPACE.has(c[j - 1])) j--;
    return c.slice(i, j).join("");
  }

  function rstrip(text) {
    const c = chars(text);
    let j = c.length;
    while (j > 0 && SPACE.has(c[j - 1])) j--;
    return c.slice(0, j).join("");
  }

  function splitWhite(text) {
    // str.split(): runs of whitespace, no empty parts
    const parts = [];
    let part = "";
    for (const ch of chars(text)) {
      if (SPACE.has(ch)) {
        if (part) parts.push(part);
        part = "";
      } else {
        part += ch;
      }
    }
    if (part) parts.push(part);
    return parts;
  }

  function pyRepr(text) {
    // repr() of a str
    const quote = text.includes("'") && !text.includes('"') ? '"' : "'";
    let out = quote;
    for (const ch of chars(text)) {
      const cp = ch.codePointAt(0);
      if (ch === quote || ch === "\\") out += "\\" + ch;
      else if (ch === "\t") out += "\\t";
      else if (ch === "\n") out += "\\n";
      else if (ch === "\r") out += "\\r";
      else if (ch !== " " && NON_PRINTABLE.test(ch)) {
        if (cp < 0x100) out += "\\x" + cp.toString(16).padStart(2, "0");
        else if (cp < 0x10000) out += "\\u" + cp.toString(16).padStart(4, "0");
        else out += "\\U" + cp.toString(16).padStart(8, "0");
      } else out += ch;
    }
    return out + quote;
  }

  function shorten(text, limit) {
    // tpm_viz.core.numbers.shorten
    const most = limit === undefined ? QUOTE : limit;
    const c = chars(String(text));
    if (c.length <= most) return pyRepr(String(text));
    return pyRepr(c.slice(0, Math.max(most - 3, 1)).join("")) + "...";
  }

  const FLOAT = /^[+-]?(?:(?:[0-9](?:_?[0-9])*)?\.[0-9](?:_?[0-9])*|[0-9](?:_?[0-9])*\.?)(?:[eE][+-]?[0-9](?:_?[0-9])*)?$/;

  function pyFloat(text) {
    // float(text): Unicode digits and spaces as Python reads them, underscores between digits; null if refused
    let ascii = "";
    for (const ch of chars(text)) {
      const cp = ch.codePointAt(0);
      if (cp < 128) ascii += ch;
      else if (SPACE.has(ch)) ascii += " ";
      else if (decimalValue(ch) >= 0) ascii += String(decimalValue(ch));
      else return null;
    }
    const s = ascii.replace(/^[ \t\n\v\f\r]+|[ \t\n\v\f\r]+$/g, "");
    const special = /^([+-]?)(inf|infinity|nan)$/i.exec(s);
    if (special) {
      if (special[2].toLowerCase() === "nan") return NaN;
      return special[1] === "-" ? -Infinity : Infinity;
    }
    return FLOAT.test(s) ? Number(s.replace(/_/g, "")) : null;
  }

  // ------------------------------------------------------------------ numbers as people type them
  const MINUS = /[\u2212\uff0d\ufe63]/gu;
  const GROUP_SPACES = "\u0020\u00a0\u202f\u2009\u2007";
  const GROUPED = new RegExp(
    "^[+-]?\\p{Nd}{1,3}(?:[" + GROUP_SPACES + "]\\p{Nd}{3})+(?:[.,]\\p{Nd}*)?(?:[eE][+-]?\\p{Nd}+)?$",
    "u",
  );
  const NUMBERISH = /^[+-]?(?:\p{Nd}+\.?\p{Nd}*|\.\p{Nd}+)(?:[eE][+-]?\p{Nd}+)?$/u;
  const WITH_UNIT = new RegExp(
    "^([\\s\\S]*[0-9.,])" + WS + "*([^0-9" + WS_CHARS + ".,+\\-\\u2212\\uff0d][^" + WS_CHARS + "]*)$",
    "u",
  );

  function label(name, unit) {
    const named = typeof name === "string" ? chars(name).slice(0, QUOTE).join("") : name;
    return unit ? P("{name} [{unit}]", { name: named, unit }) : named;
  }

  function parseNumber(text, name, unit) {
    // tpm_viz.core.numbers.parse_number for a typed text: the finite number it spells, else throws a phrase
    const lab = label(name, unit);
    let s = strip(text);
    if (!s) throw P("{label} is empty: type a number such as 0.25, 0,25 or 2.5e-1", { label: lab });
    if (chars(s).length > MAX_TEXT) {
      throw P("{label}: {text} is too long for a number ({n} characters; at most {most})", {
        label: lab, text: shorten(s), n: chars(s).length, most: MAX_TEXT,
      });
    }
    s = s.replace(MINUS, "-");
    if (unit && s.endsWith(unit) && s.length > unit.length) s = rstrip(s.slice(0, s.length - unit.length));
    if (GROUPED.test(s)) s = chars(s).filter((ch) => !GROUP_SPACES.includes(ch)).join("");
    if (s.includes(",")) {
      if (s.includes(".") || s.split(",").length > 2) {
        throw P(
          "{label}: {text} mixes separators; write the number without thousands separators, with one decimal " +
            "point or comma (1234.5 or 1234,5)",
          { label: lab, text: shorten(strip(text)) },
        );
      }
      s = s.replace(",", ".");
    }
    const value = pyFloat(s);
    if (value === null) {
      throw P("{label}: {text} is not a number (examples: 0.25, 0,25, -1.5e-3)", { label: lab, text: shorten(strip(text)) });
    }
    if (!Number.isFinite(value)) {
      if (NUMBERISH.test(s.replace(/_/g, ""))) {
        throw P("{label}: {text} is too large (beyond ±1.8e308)", { label: lab, text: shorten(strip(text)) });
      }
      throw P("{label}: {text} is not finite; type a finite number", { label: lab, text: shorten(strip(text)) });
    }
    return value;
  }

  function unitEntry(unit) {
    // tpm_viz.core.numbers._entry: [quantity, multiplier, divisor] of a unit as people write it, or null; a capital
    // M is never taken (mega is not a prefix here: "MN" must not read as "mN")
    if (unit.startsWith("M")) return null;
    let key = unit.toLowerCase().replace(/ /g, "").replace(/[µμ]/g, "u").replace(/²/g, "^2");
    if (key.endsWith("/s2")) key = key.slice(0, -1) + "^2";
    return Object.prototype.hasOwnProperty.call(CONFIG.units, key) ? CONFIG.units[key] : null;
  }

  function unitFactor(unit, quantity, lab, name) {
    // tpm_viz.core.numbers.unit_factor
    if (!unit) return [1.0, 1.0];
    const entry = unitEntry(unit);
    const si = CONFIG.si[quantity || ""] || "";
    if (entry === null) {
      if (!si) throw P("{label} has an unknown unit {unit}", { label: lab, unit: shorten(unit) });
      const alt = CONFIG.alt[si] || si;
      throw P("{label} has an unknown unit {unit} (use {si} or {alt})", { label: lab, unit: shorten(unit), si, alt });
    }
    if (quantity !== entry[0]) {
      const kind = P(CONFIG.quantities[entry[0]]);
      if (!quantity) {
        throw P("{label}: {unit} is a {kind} unit, but {name} takes no unit", { label: lab, unit: shorten(unit), kind, name });
      }
      const what = quantity in CONFIG.quantities ? P(CONFIG.quantities[quantity]) : quantity;
      throw P("{label}: {unit} is a {kind} unit, but {name} is a {quantity} in {si}", {
        label: lab, unit: shorten(unit), kind, name, quantity: what, si,
      });
    }
    return [entry[1], entry[2]];
  }

  function englishOf(name) {
    return typeof name === "string" ? name : fill(name.template, name.values); // str(phrase): English
  }

  function parseQuantity(text, name, unit) {
    // tpm_viz.core.numbers.parse_quantity: a number with any unit of the field's quantity after it
    let found = null;
    try {
      return parseNumber(text, name, unit);
    } catch (exc) {
      if (!isPhrase(exc)) throw exc;
      found = chars(text).length <= MAX_TEXT ? WITH_UNIT.exec(strip(text)) : null;
      if (found === null || !chars(found[1]).some(isDigit)) throw exc;
    }
    const head = found[1];
    const typed = found[2];
    const lab = label(name, unit);
    if (!unit) throw P("{label}: {unit} does not fit: type the number alone", { label: lab, unit: shorten(typed) });
    const field = unitEntry(unit);
    if (field === null) throw P("{label} has an unknown unit {unit} (use {si})", { label: lab, unit: shorten(typed), si: unit });
    const [mul, div] = unitFactor(typed, field[0], lab, englishOf(name));
    const value = ((((parseNumber(head, name, unit) * mul) / div) * field[2]) / field[1]);
    if (!Number.isFinite(value)) throw P("{label}: {text} is too large (beyond ±1.8e308)", { label: lab, text: shorten(text) });
    return value;
  }

  // ------------------------------------------------------------------ answers (tpm_viz.app.exercises.answers)
  const BRACKETS = { "(": ")", "[": "]" };
  const UNIT_START = /^[^0-9+\-\u2212\uff0d.,]/u;
  const COMMA_SPACES = new RegExp("," + WS + "+", "u");

  function bySpaces(text) {
    const parts = [];
    for (const token of splitWhite(text)) {
      if (parts.length && UNIT_START.test(token)) parts[parts.length - 1] += " " + token;
      else parts.push(token);
    }
    return parts;
  }

  function splitValues(text, count) {
    let s = strip(text);
    const c = chars(s);
    if (c.length >= 2 && BRACKETS[c[0]] === c[c.length - 1]) s = strip(c.slice(1, -1).join(""));
    for (const split of [s.split(";"), s.split(","), s.split(COMMA_SPACES), bySpaces(s)]) {
      const parts = split.map(strip);
      if (parts.length === count && parts.every((part) => part.length > 0)) return parts;
    }
    const example = count === 2 ? "-35; 20" : Array(count).fill("1").join("; ");
    throw P("type {n} numbers separated by ';' (for example {example})", { n: count, example });
  }

  function fixed(x, spec) {
    return root.tpm.fixed(x, spec === "g" ? ".6g" : spec); // tpm_viz.core.numbers.fixed ("g" is ".6g")
  }

  function mm(x) {
    return fixed(x * 1e3, ".1f"); // tpm_viz.app.exercises.tasks._mm
  }

  function legs(ex, p) {
    // tasks._legs: d (eq. 4), cos θ_i (eq. 23) and cos(θ1 + θ2) (eq. 12) at a reachable pose p [m]
    const c = [Math.sqrt(ex.la2 - p[1] * p[1]), Math.sqrt(ex.la2 - p[0] * p[0])];
    return {
      d: [p[0] + ex.offset - c[0], p[1] + ex.offset - c[1]],
      cos: [c[0] / ex.params.l_a, c[1] / ex.params.l_a],
      det: (c[0] * c[1] - p[0] * p[1]) / ex.la2,
    };
  }

  function poseProblem(ex, p) {
    // tasks.pose_problem: why p [m] cannot be an answer, or null
    const x = mm(p[0]);
    const y = mm(p[1]);
    const la = ex.params.l_a;
    if (!(Number.isFinite(p[0]) && Number.isFinite(p[1]) && Math.abs(p[0]) < la && Math.abs(p[1]) < la)) {
      return P("({x}, {y}) mm is out of reach: each |p_j| must be below l_a = {l_a} mm", { x, y, l_a: mm(la) });
    }
    const g = legs(ex, p);
    const stroke = ex.params.stroke;
    for (let i = 0; i < 2; i++) {
      if (!(-STROKE_EDGE <= g.d[i] && g.d[i] <= stroke + STROKE_EDGE)) {
        return P("at ({x}, {y}) mm actuator {i} would be at d{i} = {d} mm, outside the stroke 0 to {stroke} mm", {
          x, y, i: i + 1, d: mm(g.d[i]), stroke: mm(stroke),
        });
      }
    }
    if (g.det <= 0.0) {
      return P(
        "({x}, {y}) mm is in the other assembly mode (det J_x = {det}, beyond the red arc): give a pose of the " +
          "working mode",
        { x, y, det: fixed(g.det, ".2f") },
      );
    }
    return null;
  }

  function poseWarning(ex, p) {
    // tasks.pose_warning: why the readable pose p [m] is too near a singularity (the app's warning thresholds)
    const g = legs(ex, p);
    const x = mm(p[0]);
    const y = mm(p[1]);
    const i = Math.abs(g.cos[1]) < Math.abs(g.cos[0]) ? 1 : 0;
    if (Math.abs(g.cos[i]) < ex.warn.inverse) {
      return P(
        "({x}, {y}) mm is near the inverse singularity (cos θ{i} = {cos}, below {limit}): choose a pose clear of it",
        { x, y, i: i + 1, cos: fixed(g.cos[i], ".2f"), limit: fixed(ex.warn.inverse, ".1f") },
      );
    }
    if (Math.abs(g.det) < ex.warn.direct) {
      return P("({x}, {y}) mm is near the direct singularity (det J_x = {det}, below {limit}): choose a pose clear of it", {
        x, y, det: fixed(g.det, ".2f"), limit: fixed(ex.warn.direct, ".1f"),
      });
    }
    return null;
  }

  function chosen(ex, text) {
    const typed = strip(text).toLowerCase();
    for (let k = 0; k < ex.options.length; k++) {
      const o = ex.options[k];
      const names = [o.key.toLowerCase(), String(k + 1), strip(o.en).toLowerCase()];
      if (o.ko) names.push(strip(o.ko).toLowerCase());
      if (names.includes(typed)) return o.key;
    }
    throw P("type the number of an option: {options}", { options: { text: ex.options_text } });
  }

  function readAnswer(ex, text) {
    // answers.read_answer: the answer as numbers in the exercise's unit(s) (or a choice's key), else throws a phrase
    if (typeof text !== "string") throw P("the answer must be text, got {got}", { got: typeof text });
    if (chars(text).length > MAX_ANSWER) {
      throw P("the answer is too long ({n} characters; at most {most})", { n: chars(text).length, most: MAX_ANSWER });
    }
    if (!strip(text)) throw P("the answer is empty: type it in the box");
    if (ex.kind === "choice") return { choice: chosen(ex, text) };
    if (ex.kind === "number") return { values: [parseQuantity(text, P("the answer"), ex.unit)] };
    const parts = splitValues(text, 2);
    const x = parseQuantity(parts[0], "p1", "mm");
    const y = parseQuantity(parts[1], "p2", "mm");
    const problem = poseProblem(ex, [x * 1e-3, y * 1e-3]);
    if (problem !== null) throw problem;
    return { values: [x, y] };
  }

  // ------------------------------------------------------------------ grading (tpm_viz.app.exercises.grading)
  function close(x, ref, rtol, atol) {
    return Math.abs(x - ref) <= atol + rtol * Math.abs(ref); // PrairieLearn's relabs rule
  }

  function judgeNumber(ex, x) {
    if (close(x, ex.ref, ex.rtol, ex.atol)) return [1.0, P("correct")];
    for (const m of ex.mistakes) {
      const hit = m.factor !== null ? close(x / m.factor, ex.ref, ex.rtol, ex.atol) : close(x, m.value, ex.rtol, ex.atol);
      if (hit) return [m.score, { text: m.feedback }];
    }
    return [0.0, { text: ex.incorrect }];
  }

  function force(ex, index, p) {
    // τ_index [N] at p [m], ṗ = 0, the variant's p̈ (eqs. 28-31, the generated C); NaN if the calculator refuses
    const out = root.tpm.inverseDynamics(ex.params, p, [0.0, 0.0], ex.ddp);
    return out.tau ? out.tau[index] : NaN;
  }

  function passes(ex, index, target, p) {
    const value = force(ex, index, p);
    return [close(value, target, ex.rtol, ex.atol), value];
  }

  function judgePose(ex, values) {
    const p = [values[0] * 1e-3, values[1] * 1e-3];
    const warning = poseWarning(ex, p);
    if (warning !== null) return [0.0, warning];
    const [ok, value] = passes(ex, ex.index, ex.target, p);
    const where = { p1: fixed(values[0], ".1f"), p2: fixed(values[1], ".1f"), symbol: ex.symbol, unit: ex.task_unit };
    if (ok) {
      return [1.0, P("correct: {symbol} = {value} {unit} at ({p1}, {p2}) mm", Object.assign({ value: fixed(value, ".2f") }, where))];
    }
    for (const m of ex.mistakes) {
      let hit;
      if (m.factor !== null) {
        const other = [p[0] / m.factor, p[1] / m.factor];
        const fits = poseProblem(ex, other) === null && poseWarning(ex, other) === null;
        hit = fits && passes(ex, ex.index, ex.target, other)[0];
      } else {
        hit = passes(ex, m.index, m.target, p)[0];
      }
      if (hit) return [m.score, { text: m.feedback }];
    }
    return [
      0.0,
      P(
        "{symbol} = {value} {unit} at ({p1}, {p2}) mm; it must be {target} within {tol} {unit}",
        Object.assign({ value: fixed(value, ".2f"), target: ex.target_text, tol: ex.tol_text }, where),
      ),
    ];
  }

  function judgeChoice(ex, key) {
    if (key === ex.right) return [1.0, P("correct")];
    const option = ex.options.find((o) => o.key === key);
    return [0.0, option.feedback !== null ? { text: option.feedback } : P("incorrect")];
  }

  function factorOf(ex, attempt) {
    // AttemptRule.factor: what attempt `attempt` (1-based) may earn; null when the ladder has no such attempt
    if (!Number.isInteger(attempt) || attempt < 1) return null;
    if (ex.ladder === null) return 1.0;
    return attempt <= ex.ladder.length ? ex.ladder[attempt - 1] : null;
  }

  function grade(ex, text, attempt) {
    // grading.grade as `tpm-viz exercise grade` prints it: {score, format_error, feedback, attempts_used}
    if (ex.kind !== "number" && ex.kind !== "pose" && ex.kind !== "choice") throw new Error(ex.kind + ": needs the app");
    const factor = factorOf(ex, attempt);
    if (factor === null) throw new Error("attempt " + attempt + ": this exercise allows " + ex.ladder.length);
    let answer;
    try {
      answer = readAnswer(ex, text);
    } catch (exc) {
      if (!isPhrase(exc)) throw exc;
      return { score: null, format_error: render(exc), feedback: null, attempts_used: 0 };
    }
    let judged;
    if (ex.kind === "number") judged = judgeNumber(ex, answer.values[0]);
    else if (ex.kind === "pose") judged = judgePose(ex, answer.values);
    else judged = judgeChoice(ex, answer.choice);
    const score = Number(fixed(judged[0] * factor, ".9f")); // round(raw * factor, 9)
    return { score, format_error: null, feedback: render(judged[1]), attempts_used: 1 };
  }

  root.tpmGrader = Object.freeze({
    grade,
    render,
    readQuantity: parseQuantity,
    factorOf,
    P,
  });
})(typeof window !== "undefined" ? window : globalThis);
