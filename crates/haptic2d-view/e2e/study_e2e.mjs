// End-to-end test of a study session's page in a real browser (Debian's Chromium, headless).
//
// Usage: node study_e2e.mjs URL ANSWERS FIRST_TRIAL END
//   URL          the page served by `haptic2d study run FILE --observer browser --device sim`
//   ANSWERS      how many trials to answer
//   FIRST_TRIAL  the trial number the page must present first (1 for a new session, the next
//                unanswered trial for a resumed one)
//   END          "none" (leave the session running: the caller stops it with SIGINT) or "stop"
//                (press Esc, the page's stop key, after the last answer)
//
// Answers alternate between clicking the large buttons and pressing the keys (1 / 2). Before each
// answer it checks: the page shows the trial number and progress, the intervals are presented in
// order (1 then 2), the buttons are disabled until the answer phase; after it, that an answer for an
// old trial and a second answer for the same trial are refused by the loop. Prints one JSON line
// {"ok":true,"answers":[{trial,choice},…],…}; exit code 0 on success.

import { check, runInBrowser } from "./browser.mjs";

const [url, answersArg, firstArg, end] = process.argv.slice(2);
if (!url || !answersArg || !firstArg || !end) {
  console.error("usage: node study_e2e.mjs URL ANSWERS FIRST_TRIAL none|stop");
  process.exit(2);
}
const nAnswers = Number(answersArg);
const firstTrial = Number(firstArg);

await runInBrowser({ name: "study_e2e.mjs", limitMs: 100_000, result: { answers: [], intervalsSeen: [] } }, async (page, result) => {
  await page.goto(url, { waitUntil: "load" });
  await page.waitForFunction(() => window.__haptic2d && window.__haptic2d.study, null, { timeout: 30_000 });
  check(await page.evaluate(() => document.body.classList.contains("study-mode")), "the page is in study mode");

  for (let i = 0; i < nAnswers; i++) {
    const trial = firstTrial + i;
    // The trial is presented: interval 1, then interval 2, then the answer phase.
    const t0 = Date.now();
    for (;;) {
      const v = await page.evaluate(() => window.__haptic2d.study);
      check(Date.now() - t0 < 30_000, `trial ${trial} reached the answer phase within 30 s (last ${JSON.stringify(v)})`);
      if (v.trial === trial && v.phase === "presenting") {
        // Buttons are disabled while an interval is presented. The phase, the buttons and the
        // prompt are read in one evaluation (one snapshot of the page: the frame handler updates
        // them together), so a phase change between reads cannot pair a new phase with an old
        // prompt.
        const snap = await page.evaluate(() => ({
          phase: window.__haptic2d.study.phase,
          disabled: [...document.querySelectorAll("#study-choices button")].every((b) => b.disabled),
          prompt: document.querySelector("#study-prompt").textContent,
        }));
        if (snap.phase === "presenting") {
          check(snap.disabled, "the answer buttons are disabled during a presentation");
          check(/Interval [12] of 2/.test(snap.prompt), `the prompt names the interval: ${snap.prompt}`);
        }
      }
      if (v.trial === trial && v.phase === "answer") break;
      check(v.trial === 0 || v.trial === trial, `the page presents trial ${trial}, not ${v.trial}`);
      await page.waitForTimeout(20);
    }
    const seen = (await page.evaluate(() => window.__haptic2d.studyTransitions))
      .filter((x) => x.trial === trial && x.phase === "presenting").map((x) => x.interval);
    check(JSON.stringify(seen) === "[1,2]", `trial ${trial}: intervals presented in order, saw ${JSON.stringify(seen)}`);
    result.intervalsSeen.push(seen);
    const progress = await page.textContent("#study-progress");
    check(progress.includes(`Trial ${trial} of at most`) && progress.includes(`${trial - 1} answered`),
      `the progress line: ${progress}`);
    await page.waitForFunction(() => [...document.querySelectorAll("#study-choices button")].every((b) => !b.disabled), null, { timeout: 5_000 });
    const choice = (i % 3 === 1) ? 1 : 2;
    if (i % 2 === 0) {
      await page.click(`#study-choices button[data-choice="${choice}"]`);
    } else {
      await page.keyboard.press(String(choice));
    }
    result.answers.push({ trial, choice, by: i % 2 === 0 ? "click" : "key" });
    // The loop takes it: the done count moves on.
    await page.waitForFunction((t) => { const v = window.__haptic2d.study; return v && v.done >= t && v.last_saved === t; },
      trial, { timeout: 10_000 });
    // An answer for the old trial (a late double click) is refused and changes nothing.
    const before = await page.evaluate(() => window.__haptic2d.study.refused);
    await page.evaluate((t) => window.__haptic2d.send({ type: "answer", trial: t, choice: 1 }), trial);
    await page.waitForFunction((b) => window.__haptic2d.study.refused > b, before, { timeout: 5_000 });
    const after = await page.evaluate(() => window.__haptic2d.study);
    check(after.done === trial, `the refused answer did not count (done ${after.done})`);
  }
  if (end === "stop") {
    await page.keyboard.press("Escape");
    await page.waitForFunction(() => window.__haptic2d.study && window.__haptic2d.study.phase === "stopping"
      || !window.__haptic2d.connected, null, { timeout: 10_000 });
  }
});
