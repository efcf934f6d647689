/* page_scorm.js: the offline lesson page inside an LMS, through the SCORM 1.2 run-time API (docs/takehome.md). The
 * API object is found with the standard walk (ADL's findAPI: up window.parent at most 7 times, then window.opener's
 * parents; a window of another origin is skipped). Outside an LMS there is none and nothing happens.
 *
 * Inside one: LMSInitialize(""); the stored attempts come back from cmi.suspend_data when this browser has none; then
 * after every graded attempt (and once at the start) cmi.core.score.raw = round(100 x / y) with score.min 0 and
 * score.max 100, cmi.core.lesson_status (the rule below), cmi.suspend_data (the attempts, when they fit in SCORM
 * 1.2's 4096 characters) and cmi.core.exit ("suspend" while incomplete), then LMSCommit(""); when the page is left
 * (pagehide, beforeunload or unload, whichever comes first), once: the report, cmi.core.session_time (the time since
 * LMSInitialize) and LMSFinish("").
 *
 * lesson_status: "incomplete" until every exercise the page grades has at least one graded attempt; then "passed" if
 * score.raw reaches the mastery score (the LMS's cmi.student_data.mastery_score if it gives one, else the page's
 * pass_percent, 80), else "completed". A lesson whose exercises all need the app is "completed" on arrival.
 *
 *   window.tpmPage.scorm   {api, calls} (calls: every API call this page made, for tests and support)
 */
(function () {
  "use strict";
  const page = window.tpmPage;
  const DATA = page.data;

  function findAPI(win) {
    let tries = 0;
    while (win) {
      try {
        if (win.API) return win.API;
      } catch (err) {
        /* a window of another origin: keep climbing */
      }
      if (!win.parent || win.parent === win || ++tries > 7) return null;
      win = win.parent;
    }
    return null;
  }

  function getAPI() {
    let api = findAPI(window);
    try {
      if (api === null && window.opener) api = findAPI(window.opener);
    } catch (err) {
      api = null;
    }
    return api;
  }

  const api = getAPI();
  const calls = [];
  page.scorm = { api, calls };
  if (api === null) return;

  function call(name, ...args) {
    calls.push([name, ...args]);
    try {
      return String(api[name](...args));
    } catch (err) {
      return "false";
    }
  }

  if (call("LMSInitialize", "") !== "true") return;
  const started = Date.now();
  let finished = false;
  const mastery = (function () {
    const given = call("LMSGetValue", "cmi.student_data.mastery_score").trim();
    const value = given === "" ? NaN : Number(given);
    return Number.isFinite(value) && value >= 0 && value <= 100 ? value : DATA.pass_percent;
  })();

  try {
    const suspended = call("LMSGetValue", "cmi.suspend_data");
    if (suspended && suspended !== "false") page.restore(JSON.parse(suspended));
  } catch (err) {
    /* not ours, or not JSON: ignored */
  }

  function status(s) {
    if (s.y === 0) return "completed";
    if (s.answered < s.y) return "incomplete";
    return (100 * s.x) / s.y >= mastery ? "passed" : "completed";
  }

  page.report = function (s) {
    if (finished) return;
    const lesson = status(s);
    if (s.y > 0) {
      call("LMSSetValue", "cmi.core.score.raw", String(Math.round((100 * s.x) / s.y)));
      call("LMSSetValue", "cmi.core.score.min", "0");
      call("LMSSetValue", "cmi.core.score.max", "100");
    }
    call("LMSSetValue", "cmi.core.lesson_status", lesson);
    const suspend = JSON.stringify(s.state);
    if (suspend.length <= 4096) call("LMSSetValue", "cmi.suspend_data", suspend);
    call("LMSSetValue", "cmi.core.exit", lesson === "incomplete" ? "suspend" : "");
    call("LMSCommit", "");
  };

  function timespan(seconds) {
    // SCORM 1.2's CMITimespan, HHHH:MM:SS.SS
    const h = Math.floor(seconds / 3600);
    const m = Math.floor((seconds % 3600) / 60);
    const s = (seconds % 60).toFixed(2).padStart(5, "0");
    return String(Math.min(h, 9999)).padStart(4, "0") + ":" + String(m).padStart(2, "0") + ":" + s;
  }

  function finish() {
    if (finished) return;
    page.report(page.score());
    finished = true;
    call("LMSSetValue", "cmi.core.session_time", timespan((Date.now() - started) / 1000));
    call("LMSFinish", "");
  }

  for (const event of ["pagehide", "beforeunload", "unload"]) window.addEventListener(event, finish);
  page.report(page.score());
})();
