// End-to-end test of a magnitude-estimation study with rest breaks on the page, in headless
// Chromium (crates/haptic2d-cli/tests/it/browser_study.rs runs it).
//
// Usage: node study_break_magnitude_e2e.mjs URL ANSWERS BREAK_BEFORE
//   URL           the page of `haptic2d study run FILE --observer browser --device sim` (a
//                 magnitude study with [breaks])
//   ANSWERS       how many trials to answer (from trial 1), then stop with Esc
//   BREAK_BEFORE  the trial a break comes before (e.g. 3 with `every = 2`)
//
// Per trial: the page shows a number entry (no choice buttons); a word and a negative number are
// refused on the page with a message and nothing is sent; a number is typed and Enter submits it.
// Before BREAK_BEFORE the page shows the full-page break screen, the trial is not presented while it
// lasts (1 s watched), a continue for another trial is refused by the loop, and Space continues.
// Prints one JSON line {"ok":true,"answers":[{trial,magnitude}],…}; exit code 0 on success.

import { check, runInBrowser } from "./browser.mjs";

const [url, answersArg, breakArg] = process.argv.slice(2);
if (!url || !answersArg || !breakArg) {
  console.error("usage: node study_break_magnitude_e2e.mjs URL ANSWERS BREAK_BEFORE");
  process.exit(2);
}
const nAnswers = Number(answersArg);
const breakBefore = Number(breakArg);

await runInBrowser({ name: "study_break_magnitude_e2e.mjs", limitMs: 100_000, result: { answers: [], breakSeen: false } }, async (page, result) => {
  await page.goto(url, { waitUntil: "load" });
  await page.waitForFunction(() => window.__haptic2d && window.__haptic2d.study, null, { timeout: 30_000 });
  const view = () => page.evaluate(() => window.__haptic2d.study);

  for (let trial = 1; trial <= nAnswers; trial++) {
    if (trial === breakBefore) {
      await page.waitForFunction((t) => { const v = window.__haptic2d.study; return v.trial === t && v.phase === "break"; },
        trial, { timeout: 30_000 });
      const shown = await page.evaluate(() => ({
        cls: document.body.classList.contains("study-break"),
        visible: getComputedStyle(document.querySelector("#study-break")).display !== "none",
        text: document.querySelector("#study-break").textContent,
      }));
      check(shown.cls && shown.visible && /Take a break/.test(shown.text), `the break screen: ${JSON.stringify(shown)}`);
      result.breakSeen = true;
      // The loop holds: the trial is not presented during the break.
      await page.waitForTimeout(1000);
      check((await view()).phase === "break", "the break lasts until the participant continues");
      const before = (await view()).refused;
      await page.evaluate((t) => window.__haptic2d.send({ type: "continue_study", trial: t }), trial + 1);
      await page.waitForFunction((b) => window.__haptic2d.study.refused > b, before, { timeout: 5_000 });
      check((await view()).phase === "break", "a continue for another trial is refused");
      await page.keyboard.press(" ");
      await page.waitForFunction(() => window.__haptic2d.study.phase !== "break", null, { timeout: 5_000 });
      check(!(await page.evaluate(() => document.body.classList.contains("study-break"))), "the break screen is gone");
    }
    await page.waitForFunction((t) => { const v = window.__haptic2d.study; return v.trial === t && v.phase === "answer"; },
      trial, { timeout: 30_000 });
    await page.waitForFunction(() => !document.querySelector("#study-magnitude-input").disabled, null, { timeout: 5_000 });
    const ui = await page.evaluate(() => ({
      buttons: document.querySelectorAll("#study-choices button").length,
      prompt: document.querySelector("#study-prompt").textContent,
      visible: getComputedStyle(document.querySelector("#study-magnitude")).display !== "none",
    }));
    check(ui.buttons === 0 && ui.visible, `a number entry, no choice buttons: ${JSON.stringify(ui)}`);
    check(/The first is 100/.test(ui.prompt), `the prompt names the modulus: ${ui.prompt}`);
    // Refused on the page: nothing is sent.
    for (const bad of ["abc", "-5", "0"]) {
      const sent = (await page.evaluate(() => window.__haptic2d.answersSent)).length;
      await page.fill("#study-magnitude-input", bad);
      await page.press("#study-magnitude-input", "Enter");
      const err = await page.textContent("#study-magnitude-error");
      check(/not a number above 0/.test(err), `"${bad}" is refused on the page: ${err}`);
      check((await page.evaluate(() => window.__haptic2d.answersSent)).length === sent, `"${bad}" was not sent`);
    }
    const magnitude = 80 + 15 * trial + 0.5;
    await page.fill("#study-magnitude-input", String(magnitude));
    await page.press("#study-magnitude-input", "Enter");
    result.answers.push({ trial, magnitude });
    await page.waitForFunction((t) => { const v = window.__haptic2d.study; return v.done >= t && v.last_saved === t; },
      trial, { timeout: 10_000 });
    // A second number for the answered trial (a double Enter) is refused by the loop.
    const before = (await view()).refused;
    await page.evaluate((t) => window.__haptic2d.send({ type: "magnitude", trial: t, value: 5 }), trial);
    await page.waitForFunction((b) => window.__haptic2d.study.refused > b, before, { timeout: 5_000 });
  }
  await page.keyboard.press("Escape");
  await page.waitForFunction(() => window.__haptic2d.study && window.__haptic2d.study.phase === "stopping"
    || !window.__haptic2d.connected, null, { timeout: 10_000 });
  check(result.breakSeen || breakBefore > nAnswers, "the break was seen");
});
