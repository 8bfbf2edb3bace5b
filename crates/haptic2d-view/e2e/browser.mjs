// The browser harness shared by the e2e scripts: Debian's Chromium (or CHROMIUM_PATH) started
// headless by playwright-core in a throw-away profile, a watchdog, the page's errors collected,
// and the one-JSON-line verdict every script prints (exit code 0 on success, 1 on a failure).

import { chromium } from "playwright-core";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

/** Throws `what` unless `cond` holds. */
export function check(cond, what) {
  if (!cond) throw new Error(what);
}

/** Runs `body(page, result, context)` in a fresh headless Chromium page.
 *
 * name      the script, for the watchdog's message
 * limitMs   the watchdog: the process fails after this long
 * extraArgs Chromium switches on top of the quiet headless defaults
 * result    the object printed as the verdict line (`ok` is added)
 * consoleErrors  count console.error lines of the page as page errors too
 *
 * After `body` returns, no page error may have been seen. Prints the verdict line, closes the
 * browser, removes the profile and exits. */
export async function runInBrowser({ name, limitMs, extraArgs = [], result = {}, consoleErrors = false }, body) {
  const watchdog = setTimeout(() => {
    console.error(`FAIL: ${name} did not finish within ${limitMs / 1000} s`);
    process.exit(1);
  }, limitMs);
  const userDataDir = mkdtempSync(join(tmpdir(), "haptic2d-e2e-"));
  let context;
  let code = 0;
  try {
    context = await chromium.launchPersistentContext(userDataDir, {
      executablePath: process.env.CHROMIUM_PATH || "/usr/bin/chromium",
      headless: true,
      viewport: { width: 1400, height: 900 },
      args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync", ...extraArgs],
    });
    const page = context.pages()[0] || (await context.newPage());
    const pageErrors = [];
    page.on("pageerror", (e) => pageErrors.push(String(e)));
    if (consoleErrors) {
      page.on("console", (m) => {
        if (m.type() === "error") pageErrors.push(m.text());
      });
    }
    await body(page, result, context);
    check(pageErrors.length === 0, `page errors: ${JSON.stringify(pageErrors)}`);
    console.log(JSON.stringify({ ok: true, ...result }));
  } catch (e) {
    console.log(JSON.stringify({ ok: false, error: String(e && e.message ? e.message : e), ...result }));
    console.error(`FAIL: ${e && e.stack ? e.stack : e}`);
    code = 1;
  } finally {
    clearTimeout(watchdog);
    if (context) await context.close().catch(() => {});
    rmSync(userDataDir, { recursive: true, force: true });
  }
  process.exit(code);
}
