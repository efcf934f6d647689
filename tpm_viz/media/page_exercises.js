/* page_exercises.js: the lesson's exercises in the offline page (docs/takehome.md). Each answer is graded in the page
 * by window.tpmGrader (page_grader.js: the rules of tpm_viz.app.exercises) as `tpm-viz exercise grade ID --seed S
 * --answer TEXT --attempt K` grades it, K being the exercise's counted attempts so far plus one (a format error is
 * no attempt; an exam's ladder allows no attempt beyond it). An exercise's score is the best of its attempts; the
 * page's score is their sum over the exercises it grades, shown as "Score: x / y" and kept in the browser
 * (localStorage, keyed by lesson and seed). Every change is told to window.tpmPage.report (the SCORM adapter).
 *
 *   window.tpmPage.grade(id, text, attempt)   the grader's JSON for an answer (nothing stored)
 *   window.tpmPage.submit(id, text)           what the Check button does: grade, store, show; returns the JSON
 *   window.tpmPage.score()                    {x, y, answered, state}: the page's score and the stored attempts
 *   window.tpmPage.restore(state)             adopt stored attempts (the LMS's suspend data) when none are here
 */
(function () {
  "use strict";
  const page = window.tpmPage;
  const DATA = page.data;
  const W = page.W;
  const byId = {};
  for (const ex of DATA.exercises) byId[ex.id] = ex;
  const graded = DATA.exercises.filter((ex) => ex.graded);
  let state = load();

  function load() {
    try {
      const text = window.localStorage.getItem(DATA.storage_key);
      const stored = text ? JSON.parse(text) : {};
      return stored && typeof stored === "object" ? stored : {};
    } catch (err) {
      return {}; // storage disabled or unreadable: this visit only
    }
  }

  function save() {
    try {
      window.localStorage.setItem(DATA.storage_key, JSON.stringify(state));
    } catch (err) {
      /* storage disabled or full: the score stays for this visit */
    }
  }

  function scoresOf(id) {
    const entry = state[id];
    return entry && Array.isArray(entry.scores) ? entry.scores.filter((s) => typeof s === "number" && s >= 0 && s <= 1) : [];
  }

  function best(id) {
    const scores = scoresOf(id);
    return scores.length ? Math.max(...scores) : null;
  }

  function score() {
    let x = 0;
    let answered = 0;
    for (const ex of graded) {
      const b = best(ex.id);
      if (b !== null) {
        x += b;
        answered += 1;
      }
    }
    return { x, y: graded.length, answered, state: JSON.parse(JSON.stringify(state)) };
  }

  function number(x) {
    return window.tpm ? window.tpm.fixed(x, ".3g") : String(Math.round(x * 1000) / 1000);
  }

  function showScore() {
    const s = score();
    const text = W("Score: {x} / {y}", { x: number(s.x), y: s.y });
    for (const id of ["tpm-score", "tpm-score-line"]) {
      const element = document.getElementById(id);
      if (element) element.textContent = s.y > 0 ? text : ""; // a lesson without graded exercises shows no score
    }
    for (const ex of graded) {
      const card = document.getElementById("ex-" + ex.id);
      const used = scoresOf(ex.id).length;
      const left = ex.ladder === null ? null : Math.max(0, ex.ladder.length - used);
      card.querySelector(".tpm-left").textContent =
        left === null ? "" : left > 0 ? W("attempts left: {n}", { n: left }) : W("no attempts left");
      card.querySelector(".tpm-check").disabled = left === 0;
    }
    if (typeof page.report === "function") page.report(s);
    return s;
  }

  function grade(id, text, attempt) {
    const ex = byId[id];
    if (!ex) throw new Error("no exercise " + id);
    return window.tpmGrader.grade(ex, text, attempt);
  }

  function submit(id, text) {
    const ex = byId[id];
    const card = document.getElementById("ex-" + id);
    const line = card.querySelector(".tpm-feedback");
    const used = scoresOf(id).length;
    if (ex.ladder !== null && used >= ex.ladder.length) {
      line.className = "tpm-feedback format";
      line.textContent = W("no attempts left");
      return null;
    }
    const result = grade(id, text, used + 1);
    if (result.format_error !== null) {
      line.className = "tpm-feedback format";
      line.textContent = W("not graded, no attempt used: {why}", { why: result.format_error });
      return result;
    }
    const entry = state[id] && Array.isArray(state[id].scores) ? state[id] : { scores: [], answers: [] };
    entry.scores = scoresOf(id).concat([result.score]);
    entry.answers = (Array.isArray(entry.answers) ? entry.answers : []).concat([String(text).slice(0, 200)]);
    state[id] = entry;
    save();
    line.className = "tpm-feedback " + (result.score >= 1 ? "right" : result.score > 0 ? "partial" : "wrong");
    const tally = W("attempt {k}: score {score}; best {best}", {
      k: entry.scores.length, score: number(result.score), best: number(best(id)),
    });
    line.textContent = result.feedback + " (" + tally + ")";
    showScore();
    return result;
  }

  function restore(stored) {
    // adopt stored attempts (e.g. the LMS's cmi.suspend_data) when this browser has none for the page
    if (Object.keys(state).length || !stored || typeof stored !== "object") return false;
    state = stored;
    save();
    showScore();
    return true;
  }

  function answerOf(card, ex) {
    if (ex.kind === "choice") {
      const picked = card.querySelector("input[type=radio]:checked");
      return picked ? picked.value : "";
    }
    return card.querySelector(".tpm-answer-text").value;
  }

  for (const ex of graded) {
    const card = document.getElementById("ex-" + ex.id);
    const check = card.querySelector(".tpm-check");
    const box = card.querySelector(".tpm-answer-text");
    const go = () => window.tpmReady.then(() => submit(ex.id, answerOf(card, ex)));
    check.addEventListener("click", go);
    if (box) {
      box.addEventListener("keydown", (event) => {
        if (event.key === "Enter") go();
      });
    }
    const use = card.querySelector(".tpm-use-pose");
    if (use) {
      use.addEventListener("click", () => {
        // "Use current pose" (the app's button): the calculator's platform position p1; p2 in mm, as its fields show it
        const fields = document.getElementById("tpm-calculator");
        const p = ["p1", "p2"].map((k) => fields.querySelector('[data-q="' + k + '"]').value.trim());
        box.value = p.join("; ");
      });
    }
  }

  Object.assign(page, { grade, submit, score, restore, showScore });
  showScore();
  window.tpmReady.then(showScore); // the numbers in the page's format once the calculator is there
})();
