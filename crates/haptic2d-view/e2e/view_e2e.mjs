// End-to-end test of the haptic2d live display in a real browser (Debian's Chromium, headless).
//
// Usage: node view_e2e.mjs URL
//   URL                      the page served by `haptic2d run` (box-in-walls, simulated device,
//                            --hand follow), e.g. http://127.0.0.1:8080/
//   CHROMIUM_PATH            the browser (default /usr/bin/chromium)
//   HAPTIC2D_VIEW_SCREENSHOT where to save a PNG of the page after the drag (optional)
//
// Checks: the page connects and receives scene + frames; the canvas is not blank (pixel variance
// of a screenshot); dragging the hand target into the left wall moves the box there through the
// simulated hand, the device and the controller, and a contact appears (read through
// window.__haptic2d, fed by the state stream); Q rotates the target; the scene list greys out
// exactly the scenes the server says the loop cannot run at its rate; a page from another origin
// (http://evil.example, served by request interception) opening a WebSocket to the display gets a
// view-only connection whose commands are refused, and the loop's state does not change; no page
// errors and no error frames on the page. Prints one JSON line with the measurements; exit code 0
// on success.

import { check, runInBrowser } from "./browser.mjs";

const url = process.argv[2];
if (!url) {
  console.error("usage: node view_e2e.mjs URL");
  process.exit(2);
}
const screenshotPath = process.env.HAPTIC2D_VIEW_SCREENSHOT;

const extraArgs = [
  "--disable-quic",
  // Recent Chromium blocks a public page's requests to loopback itself (Local Network Access)
  // unless the user grants a permission; other browsers, older ones and a granted permission do
  // not. Step 6 tests the display's own defence, so the browser's is turned off.
  "--disable-features=LocalNetworkAccessChecks,LocalNetworkAccessChecksWebSockets,BlockInsecurePrivateNetworkRequests,PrivateNetworkAccessSendPreflights,PrivateNetworkAccessRespectPreflightResults",
];

await runInBrowser({ name: "view_e2e.mjs", limitMs: 90_000, extraArgs, consoleErrors: true }, async (page, result, context) => {
  // 1. The page loads, connects, gets the scene and frames.
  await page.goto(url, { waitUntil: "load" });
  await page.waitForFunction(
    () => window.__haptic2d && window.__haptic2d.scene && window.__haptic2d.framesForScene >= 10,
    null,
    { timeout: 20_000 },
  );
  const start = await page.evaluate(() => {
    const h = window.__haptic2d;
    const f = h.lastFrame;
    return { scene: h.scene.name, slave: h.scene.slave, pose: f.bodies[h.scene.slave], control: h.welcome.control };
  });
  result.scene = start.scene;
  result.start_pose = start.pose;
  check(start.slave !== null, "the scene has no slave body");
  check(start.control, "the page has no control (token?)");

  // 1b. A first visit explains the page; every control fits inside the panel at common widths (a grid
  //     item is as wide as its longest option unless told otherwise); "Got it" hides the hint for good.
  check(await page.isVisible("#first-visit"), "no first-visit hint on a first visit");
  const overflow = [];
  for (const width of [1280, 1400, 1920]) {
    await page.setViewportSize({ width, height: 900 });
    await page.waitForTimeout(100);
    const bad = await page.evaluate(() => {
      const panel = document.getElementById("panel").getBoundingClientRect();
      return [...document.querySelectorAll("#panel select, #panel button")]
        .filter((el) => el.offsetParent !== null)
        .map((el) => ({ id: el.id || el.textContent, r: el.getBoundingClientRect() }))
        .filter((x) => x.r.right > panel.right - 1 || x.r.left < panel.left)
        .map((x) => `${x.id}: ${x.r.left.toFixed(0)}..${x.r.right.toFixed(0)} vs panel ${panel.left.toFixed(0)}..${panel.right.toFixed(0)}`);
    });
    for (const b of bad) overflow.push(`${width} px: ${b}`);
  }
  check(overflow.length === 0, `controls overflow the panel: ${JSON.stringify(overflow)}`);
  result.layout_widths_checked = [1280, 1400, 1920];
  await page.setViewportSize({ width: 1400, height: 900 });
  await page.click("#btn-hint-ok");
  check(!(await page.isVisible("#first-visit")), "the hint stays after Got it");
  check(await page.evaluate(() => localStorage.getItem("haptic2d.hint-seen") === "1"), "the hint's dismissal is not kept");

  // 2. The canvas is not blank: pixel variance of a screenshot of it, decoded by the browser.
  const canvasShot = await page.locator("#world").screenshot();
  const stats = await page.evaluate(async (b64) => {
    const img = new Image();
    img.src = "data:image/png;base64," + b64;
    await img.decode();
    const c = new OffscreenCanvas(img.width, img.height);
    const g = c.getContext("2d");
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, img.width, img.height).data;
    let n = 0, sum = 0, sum2 = 0;
    const colours = new Set();
    for (let i = 0; i < d.length; i += 4) {
      const y = 0.299 * d[i] + 0.587 * d[i + 1] + 0.114 * d[i + 2];
      sum += y; sum2 += y * y; n++;
      if (i % 64 === 0) colours.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
    }
    const mean = sum / n;
    return { width: img.width, height: img.height, variance: sum2 / n - mean * mean, colours: colours.size };
  }, canvasShot.toString("base64"));
  result.canvas = stats;
  check(stats.variance > 100 && stats.colours > 8, `the canvas looks blank: ${JSON.stringify(stats)}`);

  // 3. Drag the hand target from the box into the left wall (x = 0): 10 mm inside the wall. The loop
  //    clamps the target to the device workspace (mapped into the world); the simulated hand pulls
  //    the handle there, and the controller drags the box into the wall.
  const [x0, y0] = start.pose;
  const from = await page.evaluate(([x, y]) => window.__haptic2d.worldToClient(x, y), [x0, y0]);
  const to = await page.evaluate(([x, y]) => window.__haptic2d.worldToClient(x, y), [-0.01, y0]);
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  await page.mouse.move(to.x, to.y, { steps: 20 });
  await page.mouse.up();
  const goal = await page.evaluate(([cx, cy]) => window.__haptic2d.clientToWorld(cx, cy), [to.x, to.y]);
  const ws = await page.evaluate(() => window.__haptic2d.scene.device.workspace);
  const expected = [Math.min(Math.max(goal[0], ws[0]), ws[2]), Math.min(Math.max(goal[1], ws[1]), ws[3])];
  result.drag_goal = goal;
  result.expected_target = expected;

  // The loop echoes the (clamped) target, the box reaches the wall (its left face, 20 mm from its
  // centre, at x ≈ 0) and the contact manager reports contacts there.
  await page.waitForFunction(
    ([ex, ey]) => {
      const f = window.__haptic2d.lastFrame;
      if (!f) return false;
      const p = f.bodies[f.slave];
      return Math.abs(f.hand_target[0] - ex) < 1e-6 && Math.abs(f.hand_target[1] - ey) < 1e-6 &&
        f.contacts_total > 0 && p[0] < 0.025;
    },
    expected,
    { timeout: 20_000 },
  );
  const hit = await page.evaluate(() => {
    const f = window.__haptic2d.lastFrame;
    return {
      t: f.t,
      pose: f.bodies[f.slave],
      contacts_total: f.contacts_total,
      contacts: f.contacts.map((c) => ({
        point: c.point, god_object: c.god_object, normal: c.normal, f_n: c.f_n, state: c.state, body_b: c.body_b,
      })),
      contact_force_n: f.contact_force_n,
      hand_target: f.hand_target,
      device_valid: f.device ? f.device.valid : null,
    };
  });
  result.hit = hit;
  check(hit.pose[0] < x0 - 0.01, `the box did not move left: ${JSON.stringify(hit.pose)}`);
  check(hit.device_valid === true, "the device linkage is not in the frames");
  // The box's left corners touch the wall's face: god-objects on the face (x = 0), normal +x, the
  // vertices inside the wall (x < 0) but not beyond the target (x > −10 mm).
  check(
    hit.contacts.some((c) => Math.abs(c.god_object[0]) < 1e-6 && c.normal[0] > 0.99 && c.point[0] < 0 && c.point[0] > -0.01),
    `no contact on the left wall's face (x = 0, normal +x): ${JSON.stringify(hit.contacts)}`,
  );
  // Held against the wall by the simulated hand (a spring pulling the handle towards a target
  // beyond the wall): a steady contact force of newtons, rendered back to the hand by the device.
  await page.waitForFunction(() => window.__haptic2d.lastFrame.contact_force_n > 1.0, null, { timeout: 10_000 });
  result.contact_force_n = await page.evaluate(() => window.__haptic2d.lastFrame.contact_force_n);

  // 4. Q rotates the hand target by +5°, and the loop echoes it.
  const theta0 = await page.evaluate(() => window.__haptic2d.lastFrame.hand_target[2]);
  await page.keyboard.press("q");
  await page.waitForFunction(
    (t0) => Math.abs(window.__haptic2d.lastFrame.hand_target[2] - (t0 + (5 * Math.PI) / 180)) < 1e-6,
    theta0,
    { timeout: 10_000 },
  );
  result.rotated = true;

  // 5. Scenes the loop cannot run at its rate are greyed out, with the reason as tooltip; the others
  //    can be chosen.
  const scenes = await page.evaluate(() => {
    const costs = window.__haptic2d.welcome.options.scene_costs;
    const opts = [...document.querySelectorAll("#sel-scene option")].map((o) => ({
      name: o.value, disabled: o.disabled, title: o.title,
    }));
    return { costs, opts };
  });
  check(Array.isArray(scenes.costs) && scenes.costs.length === scenes.opts.length,
    `scene_costs do not cover the scene list: ${JSON.stringify(scenes)}`);
  for (const c of scenes.costs) {
    const o = scenes.opts.find((x) => x.name === c.name);
    check(o && o.disabled === !c.runnable && (c.runnable || o.title === c.reason),
      `scene ${c.name}: option ${JSON.stringify(o)} does not match ${JSON.stringify(c)}`);
  }
  result.scene_costs = scenes.costs.map((c) => ({ name: c.name, step_us: c.step_us, runnable: c.runnable }));

  // 6. A page from another origin cannot command the loop. The page of http://evil.example is
  //    served by request interception (no network); its WebSocket to the display is real.
  const before = await page.evaluate(() => {
    const f = window.__haptic2d.lastFrame;
    return { wall_law: f.wall_law, controller: f.controller, paused: f.paused, scene: window.__haptic2d.scene.name };
  });
  await context.route("http://evil.example/**", (route) =>
    route.fulfill({ status: 200, contentType: "text/html", body: "<!doctype html><title>elsewhere</title><p>a page from elsewhere" }));
  const evil = await context.newPage();
  await evil.goto("http://evil.example/");
  const wsUrl = `ws://${new URL(url).host}/ws`;
  const attack = await evil.evaluate((u) => new Promise((resolve) => {
    const got = { welcome: null, errors: [], acks: [], opened: false };
    const cmds = [
      { type: "set_wall_law", name: "zoh" },
      { type: "set_controller", name: "coupling" },
      { type: "switch_scene", name: "peg-in-hole" },
      { type: "pause" },
    ];
    const ws = new WebSocket(u);
    const done = () => { try { ws.close(); } catch (e) {} resolve(got); };
    ws.onopen = () => { got.opened = true; };
    ws.onerror = () => { got.errors.push("websocket error"); done(); };
    ws.onmessage = (ev) => {
      const m = JSON.parse(ev.data);
      if (m.type === "welcome") {
        got.welcome = { control: m.control, reason: m.view_only_reason };
        for (const c of cmds) ws.send(JSON.stringify(c));
      } else if (m.type === "error") {
        got.errors.push(m.message);
        if (got.errors.length >= cmds.length) done();
      } else if (m.type === "ack") {
        got.acks.push(m.command);
      }
    };
    setTimeout(done, 10_000);
  }), wsUrl);
  result.cross_origin = attack;
  check(attack.opened && attack.welcome, `the foreign page's WebSocket did not open: ${JSON.stringify(attack)}`);
  check(attack.welcome.control === false && /evil\.example/.test(attack.welcome.reason || ""),
    `the foreign page got control: ${JSON.stringify(attack)}`);
  check(attack.acks.length === 0 && attack.errors.length === 4 &&
    attack.errors.every((e) => e.includes("only from the page")), `foreign commands not refused: ${JSON.stringify(attack)}`);
  await evil.close();
  await page.waitForTimeout(500);
  const after = await page.evaluate(() => {
    const f = window.__haptic2d.lastFrame;
    return { wall_law: f.wall_law, controller: f.controller, paused: f.paused, scene: window.__haptic2d.scene.name };
  });
  check(JSON.stringify(after) === JSON.stringify(before),
    `the loop changed after the foreign page's commands: ${JSON.stringify({ before, after })}`);

  // 7. Nothing went wrong on the way.
  const errors = await page.evaluate(() => window.__haptic2d.errors);
  check(errors.length === 0, `error frames: ${JSON.stringify(errors)}`);
  // Acknowledgements read as information, not as errors: not in the error colour. (Setting the
  // wall law it already has is acknowledged and changes nothing.)
  const law = await page.evaluate(() => window.__haptic2d.lastFrame.wall_law);
  await page.evaluate((w) => window.__haptic2d.send({ type: "set_wall_law", name: w }), law);
  await page.waitForFunction(() => window.__haptic2d.acks.length > 0, null, { timeout: 10_000 });
  const ackColours = await page.evaluate(() =>
    [...document.querySelectorAll("#errors div:not(.err)")].map((d) => getComputedStyle(d).color));
  check(ackColours.length > 0, "no acknowledgement line in Messages");
  check(ackColours.every((c) => c !== "rgb(201, 42, 42)"), `acknowledgements in red: ${JSON.stringify(ackColours)}`);
  result.frames_received = await page.evaluate(() => window.__haptic2d.framesReceived);

  if (screenshotPath) {
    await page.waitForTimeout(300);
    await page.screenshot({ path: screenshotPath });
    result.screenshot = screenshotPath;
  }
});
