// haptic2d live view: plain JavaScript + canvas, no build step.
//
// Protocol (JSON text over /ws): the server sends {type: "welcome" | "scene" | "frame" | "ack" |
// "error"}; the page sends commands {type: "set_hand_target", x, y, theta} (world frame, m, rad),
// {type: "switch_scene" | "set_wall_law" | "set_friction" | "set_impact_friction" | "set_controller", name},
// {type: "pause" | "resume" | "reset"} and {type: "hello", token}.
"use strict";

(function () {
  const $ = (id) => document.getElementById(id);
  const params = new URLSearchParams(location.search);
  const token = params.get("token");

  // State shared with tests through window.__haptic2d.
  const state = {
    connected: false,
    welcome: null,
    scene: null,
    lastFrame: null,
    framesReceived: 0,
    framesForScene: 0,
    errors: [],
    acks: [],
    commandsSent: 0,
    target: null, // [x, y, theta] the page last asked for
  };

  // ---------------------------------------------------------------- connection
  let ws = null;
  let retryMs = 500;

  function setStatus(kind, text) {
    const el = $("status");
    el.className = kind;
    $("status-text").textContent = text;
  }

  function logMessage(text, isError) {
    const line = `${new Date().toLocaleTimeString()} ${text}`;
    if (isError) state.errors.push(text);
    // Newest first; errors in red, acknowledgements in the neutral text colour; at most 60 lines.
    const pre = $("errors");
    const div = document.createElement("div");
    div.textContent = line;
    if (isError) div.className = "err";
    pre.prepend(div);
    while (pre.childElementCount > 60) pre.lastElementChild.remove();
  }

  function connect() {
    const proto = location.protocol === "https:" ? "wss:" : "ws:";
    const url = `${proto}//${location.host}/ws${token ? "?token=" + encodeURIComponent(token) : ""}`;
    setStatus("connecting", "connecting…");
    ws = new WebSocket(url);
    ws.onopen = () => {
      state.connected = true;
      retryMs = 500;
      setStatus("open", "connected");
    };
    ws.onclose = () => {
      state.connected = false;
      setStatus("closed", `disconnected — retrying in ${(retryMs / 1000).toFixed(1)} s`);
      setTimeout(connect, retryMs);
      retryMs = Math.min(retryMs * 2, 5000);
    };
    ws.onerror = () => {};
    ws.onmessage = (ev) => {
      let msg;
      try {
        msg = JSON.parse(ev.data);
      } catch (e) {
        logMessage("unreadable message from the server", true);
        return;
      }
      switch (msg.type) {
        case "frame": onFrame(msg); break;
        case "scene": onScene(msg); break;
        case "welcome": onWelcome(msg); break;
        case "ack": state.acks.push(msg.command); logMessage(`ok: ${msg.command}`, false); break;
        case "error": logMessage(`error: ${msg.message}`, true); break;
        default: break;
      }
    };
  }

  function send(obj) {
    if (!ws || ws.readyState !== WebSocket.OPEN) return false;
    ws.send(JSON.stringify(obj));
    state.commandsSent += 1;
    return true;
  }

  // ---------------------------------------------------------------- messages
  // `refused` maps a name to the reason it cannot be chosen (greyed out, the reason as tooltip).
  // What the comparison controllers are (the names are those of `haptic2d run --controller`).
  const NOTES = {
    "four-channel": ["", "default: slave- and master-side local force feedback (C5 = 2, C6 = -1) with master damping, from the design study of docs/MODELS.md §11.4; stable with the hand released"],
    "four-channel-spec": ["(unstable released)", "the paper's §11.1 gains: unstable with the hand released against a stiff contact (comparison)"],
    "four-channel-damped": ["(comparison)", "the §11.1 gains with 40 N·s/m of master damping injection (comparison)"],
  };

  function fillSelect(sel, names, type, refused) {
    sel.innerHTML = "";
    for (const n of names) {
      const o = document.createElement("option");
      o.value = n; o.textContent = n;
      const note = type === "set_controller" && NOTES[n];
      if (note) {
        if (note[0]) o.textContent = `${n} ${note[0]}`;
        o.title = note[1];
      }
      const why = refused && refused.get(n);
      if (why) {
        o.disabled = true;
        o.title = why;
        o.textContent = `${n} (too heavy for this rate)`;
      }
      sel.appendChild(o);
    }
    sel.onchange = () => send({ type, name: sel.value });
  }

  function onWelcome(msg) {
    state.welcome = msg;
    const o = msg.options;
    // Scenes whose world step does not fit the loop's period (the server refuses them too).
    const heavy = new Map((o.scene_costs || []).filter((c) => !c.runnable).map((c) => [c.name, c.reason]));
    fillSelect($("sel-scene"), o.scenes, "switch_scene", heavy);
    fillSelect($("sel-wall"), o.wall_laws, "set_wall_law");
    fillSelect($("sel-friction"), o.friction_models, "set_friction");
    fillSelect($("sel-impact-friction"), o.impact_friction_modes || [], "set_impact_friction");
    fillSelect($("sel-controller"), o.controllers, "set_controller");
    const ctl = msg.control;
    for (const id of ["sel-scene", "sel-wall", "sel-friction", "sel-impact-friction", "sel-controller", "btn-pause", "btn-reset"]) {
      $(id).disabled = !ctl;
    }
    $("control-hint").textContent = ctl ? "" :
      (msg.view_only_reason || "view only: commands need the token printed at startup (open the page with ?token=…)");
    if (state.scene) $("sel-scene").value = state.scene.name;
  }

  function onScene(msg) {
    state.scene = msg;
    state.framesForScene = 0;
    state.target = null;
    $("scene-name").textContent = msg.name;
    if ($("sel-scene").options.length) $("sel-scene").value = msg.name;
    charts.forEach((c) => c.clear());
    fitView(null);
  }

  let frameTimes = [];
  function onFrame(f) {
    if (state.scene && f.scene_seq !== state.scene.seq) return; // a frame of another scene
    state.lastFrame = f;
    if (!view.fitted) fitView(f);
    state.framesReceived += 1;
    state.framesForScene += 1;
    const now = performance.now();
    frameTimes.push(now);
    while (frameTimes.length && now - frameTimes[0] > 2000) frameTimes.shift();
    if (state.target === null) state.target = f.hand_target.slice();
    if (!dragging) state.target = f.hand_target.slice();
    charts[0].push(f.t, [f.contact_force_n, f.contact_force_t]);
    charts[1].push(f.t, [f.energy.kinetic * 1e3, f.energy.stored * 1e3, f.energy.applied_work * 1e3,
      f.energy.passivity == null ? NaN : f.energy.passivity * 1e3]);
    charts[2].push(f.t, [f.timing.lateness_p50_us, f.timing.lateness_p99_us, f.timing.lateness_max_us]);
    updatePanel(f);
    updateStudy(f.study);
  }

  // ---------------------------------------------------------------- study (haptic2d study run --observer browser)
  const CHOICES = {
    "2afc": { q: "Which interval was stiffer?", c: [[1, "First", "1"], [2, "Second", "2"]] },
    "3afc": { q: "Which interval was stiffest?", c: [[1, "First", "1"], [2, "Second", "2"], [3, "Third", "3"]] },
    "same-different": { q: "Were the two intervals the same or different?", c: [[0, "Same", "S"], [1, "Different", "D"]] },
    // Magnitude estimation: a number entry instead of buttons (no choice keys).
    "magnitude": { q: "How stiff was the second interval? The first is MODULUS: type a number above 0, then Enter.", c: [] },
  };
  // The largest number the server takes (haptic2d_view::command::MAX_MAGNITUDE).
  const MAX_MAGNITUDE = 1e9;
  const study = { view: null, built: "", answeredTrial: 0, sent: [], transitions: [] };
  function updateStudy(v) {
    const last = study.transitions[study.transitions.length - 1];
    if (v && (!last || last.trial !== v.trial || last.phase !== v.phase || last.interval !== v.interval)) {
      study.transitions.push({ trial: v.trial, phase: v.phase, interval: v.interval });
      if (study.transitions.length > 500) study.transitions.shift();
    }
    study.view = v || null;
    document.body.classList.toggle("study-mode", !!v);
    if (!v) return;
    const spec = CHOICES[v.task] || CHOICES["2afc"];
    const shape = `${v.task}/${v.intervals}`;
    if (study.built !== shape) {
      study.built = shape;
      $("study-choices").replaceChildren(...spec.c.map(([choice, label, key]) => {
        const b = document.createElement("button");
        b.textContent = `${label} (${key})`;
        b.dataset.choice = String(choice);
        b.onclick = () => answer(choice);
        return b;
      }));
      $("study-intervals").replaceChildren(...Array.from({ length: v.intervals }, (_, i) => {
        const sp = document.createElement("span");
        sp.textContent = `interval ${i + 1}`;
        return sp;
      }));
      $("study-keys").textContent = spec.c.length
        ? `keys: ${spec.c.map((c) => c[2]).join(" / ")} answer · Space pause · Esc stop`
        : "Enter answers · Esc stop";
      $("study-magnitude").classList.toggle("on", v.task === "magnitude");
    }
    const onBreak = v.phase === "break";
    document.body.classList.toggle("study-break", onBreak);
    if (onBreak) $("study-break-progress").textContent = `${v.done} of at most ${v.planned} answered`;
    $("study-progress").textContent = v.trial
      ? `Trial ${v.trial} of at most ${v.planned} · ${v.done} answered`
      : `${v.done} of at most ${v.planned} answered`;
    const waiting = v.phase === "answer" && study.answeredTrial !== v.trial;
    const paused = state.lastFrame && state.lastFrame.paused;
    let prompt;
    switch (v.phase) {
      case "presenting": prompt = `Interval ${v.interval} of ${v.intervals}: explore the wall (${v.remaining_s.toFixed(1)} s)`; break;
      case "free_space": prompt = `Lift the handle off the wall: interval ${v.interval} starts in free space`; break;
      case "answer": prompt = waiting ? spec.q.replace("MODULUS", String(v.modulus)) : "Saving the answer…"; break;
      case "break": prompt = "Take a break: press Continue (Space) when ready"; break;
      case "stopping": prompt = "Session stopped: the torques are off. It resumes at this trial."; break;
      default: prompt = "Next trial…";
    }
    if (paused && v.phase !== "stopping") prompt = "Paused (no force): press Space or Resume to continue";
    $("study-prompt").textContent = prompt;
    [...$("study-intervals").children].forEach((sp, i) => sp.classList.toggle("now", v.phase === "presenting" && v.interval === i + 1));
    [...$("study-choices").children].forEach((b) => { b.disabled = !waiting || paused; });
    const numberOpen = v.task === "magnitude" && waiting && !paused;
    const input = $("study-magnitude-input");
    if (input.disabled === numberOpen) {
      input.disabled = !numberOpen;
      $("study-magnitude-ok").disabled = !numberOpen;
      if (numberOpen) { input.value = ""; $("study-magnitude-error").textContent = ""; input.focus(); }
    }
    $("study-pause").textContent = paused ? "Resume (Space)" : "Pause (Space)";
  }
  function answer(choice) {
    const v = study.view;
    if (!v || v.phase !== "answer" || study.answeredTrial === v.trial) return false;
    if (state.lastFrame && state.lastFrame.paused) return false;
    if (!send({ type: "answer", trial: v.trial, choice })) return false;
    study.answeredTrial = v.trial; // one answer per trial from this page
    study.sent.push({ trial: v.trial, choice });
    [...$("study-choices").children].forEach((b) => { b.disabled = true; });
    $("study-prompt").textContent = "Saving the answer…";
    return true;
  }
  // A magnitude estimate: a finite number above 0 (the server checks it again).
  function parseMagnitude(text) {
    const t = String(text).trim().replace(",", ".");
    if (!/^[0-9]*\.?[0-9]+(e[+-]?[0-9]+)?$/i.test(t)) return null;
    const x = Number(t);
    return Number.isFinite(x) && x > 0 && x <= MAX_MAGNITUDE ? x : null;
  }
  function answerMagnitude(text) {
    const v = study.view;
    if (!v || v.task !== "magnitude" || v.phase !== "answer" || study.answeredTrial === v.trial) return false;
    if (state.lastFrame && state.lastFrame.paused) return false;
    const value = parseMagnitude(text);
    if (value === null) {
      $("study-magnitude-error").textContent = `"${String(text).slice(0, 20)}" is not a number above 0: type e.g. 120`;
      return false;
    }
    if (!send({ type: "magnitude", trial: v.trial, value })) return false;
    study.answeredTrial = v.trial;
    study.sent.push({ trial: v.trial, magnitude: value });
    $("study-magnitude-input").disabled = true;
    $("study-magnitude-ok").disabled = true;
    $("study-magnitude-error").textContent = "";
    $("study-prompt").textContent = "Saving the answer…";
    return true;
  }
  $("study-magnitude").onsubmit = (ev) => { ev.preventDefault(); answerMagnitude($("study-magnitude-input").value); };
  function continueStudy() {
    const v = study.view;
    if (!v || v.phase !== "break") return false;
    return send({ type: "continue_study", trial: v.trial });
  }
  $("study-continue").onclick = () => continueStudy();
  $("study-pause").onclick = () => send({ type: state.lastFrame && state.lastFrame.paused ? "resume" : "pause" });
  $("study-stop").onclick = () => send({ type: "stop_study" });
  window.addEventListener("keydown", (ev) => {
    const v = study.view;
    if (!v || ev.repeat) return;
    // Esc stops the session from anywhere, the number entry included.
    if (ev.key === "Escape") { send({ type: "stop_study" }); ev.preventDefault(); return; }
    if (ev.target && (ev.target.tagName === "SELECT" || ev.target.tagName === "INPUT")) return;
    if (ev.key === " " && v.phase === "break") { continueStudy(); ev.preventDefault(); return; }
    if (ev.key === " ") { $("study-pause").click(); ev.preventDefault(); return; }
    const spec = CHOICES[v.task] || CHOICES["2afc"];
    const hit = spec.c.find((c) => c[2].toLowerCase() === ev.key.toLowerCase());
    if (hit) { answer(hit[0]); ev.preventDefault(); }
  });

  function fmt(v, d) { return (v === null || v === undefined || !isFinite(v)) ? "—" : v.toFixed(d); }

  function updatePanel(f) {
    const t = f.timing;
    $("sim-time").textContent = f.t.toFixed(3);
    $("contact-count").textContent = f.contacts_total;
    $("paused-badge").style.display = f.paused ? "inline" : "none";
    $("btn-pause").textContent = f.paused ? "Resume" : "Pause";
    for (const [id, v] of [["sel-wall", f.wall_law], ["sel-friction", f.friction], ["sel-impact-friction", f.impact_friction], ["sel-controller", f.controller]]) {
      const sel = $(id);
      if (document.activeElement !== sel && sel.value !== v) sel.value = v;
    }
    $("tm-rate").textContent = `${fmt(t.rate_hz, 0)} / ${fmt(t.achieved_hz, 1)} Hz`;
    $("tm-late").textContent = `${fmt(t.lateness_p50_us, 1)} / ${fmt(t.lateness_p99_us, 1)} / ${fmt(t.lateness_max_us, 1)} µs`;
    $("tm-comp").textContent = `${fmt(t.compute_p50_us, 1)} / ${fmt(t.compute_p99_us, 1)} µs`;
    $("tm-over").textContent = `${t.overruns} / ${t.skipped}`;
    $("tm-ticks").textContent = `${t.ticks}`;
    // Frames per second over the recent frame times; "—" until two frames arrived at distinct times
    // (a paused or virtual clock gives a zero span).
    const span = frameTimes.length > 1 ? (frameTimes[frameTimes.length - 1] - frameTimes[0]) / 1000 : 0;
    const fps = span > 0 ? `${((frameTimes.length - 1) / span).toFixed(0)} /s` : "— /s";
    $("tm-frames").textContent = `${state.framesReceived} (${fps})`;
    if (f.slave !== null && f.bodies[f.slave]) {
      const p = f.bodies[f.slave];
      $("st-pos").textContent = `${fmt(p[0] * 1e3, 2)}, ${fmt(p[1] * 1e3, 2)}`;
      $("st-theta").textContent = fmt(p[2] * 180 / Math.PI, 1);
    }
    const h = f.hand_target;
    $("st-target").textContent = `${fmt(h[0] * 1e3, 1)}, ${fmt(h[1] * 1e3, 1)}, ${fmt(h[2] * 180 / Math.PI, 0)}`;
    $("st-force").textContent = `${fmt(f.contact_force_n, 3)} / ${fmt(f.contact_force_t, 3)}`;
    $("st-energy").textContent = `${fmt(f.energy.kinetic * 1e3, 3)} / ${fmt(f.energy.stored * 1e3, 3)}`;
    $("st-excess").textContent = fmt(f.energy.excess * 1e3, 4);
  }

  // ---------------------------------------------------------------- world view
  const canvas = $("world");
  const ctx = canvas.getContext("2d");
  // World → screen: sx = ox + x·scale, sy = oy − y·scale (CSS pixels, y up in the world).
  const view = { scale: 1000, ox: 0, oy: 0, w: 0, h: 0, dpr: 1, fitted: false };

  function resizeCanvas(c) {
    const dpr = window.devicePixelRatio || 1;
    const r = c.getBoundingClientRect();
    const w = Math.max(1, Math.round(r.width * dpr)), h = Math.max(1, Math.round(r.height * dpr));
    if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
    return { w: r.width, h: r.height, dpr };
  }

  // Fits the view to the scene. With a device in the loop driving the only dynamic body, and once a
  // frame is known, the view is fitted to what moves (the slave, the linkage, the device workspace)
  // rather than to the whole enclosure, so that the slave, the linkage and the force arrows are
  // large enough to read (the slave cannot leave the workspace by much). Otherwise it shows the
  // whole scene and the device.
  function fitView(frame) {
    const r = resizeCanvas(canvas);
    view.w = r.w; view.h = r.h; view.dpr = r.dpr;
    const s = state.scene;
    view.fitted = !!frame;
    if (s && s.bodies.filter((body) => !body.fixed).length > 1) frame = null;
    let b = s ? s.bounds.slice() : [-0.1, -0.1, 0.1, 0.1];
    const grow = (x, y) => { b[0] = Math.min(b[0], x); b[1] = Math.min(b[1], y); b[2] = Math.max(b[2], x); b[3] = Math.max(b[3], y); };
    if (s && s.device) {
      const m = s.device.motors, ws = s.device.workspace;
      const d = frame && frame.device && frame.device.valid ? frame.device : null;
      if (frame) {
        b = [Infinity, Infinity, -Infinity, -Infinity];
        s.bodies.forEach((body, i) => {
          const p = frame.bodies[i]; if (body.fixed || !p) return;
          let rad = 0;
          for (const piece of body.pieces) for (const [x, y] of piece) rad = Math.max(rad, Math.hypot(x, y));
          grow(p[0] - rad, p[1] - rad); grow(p[0] + rad, p[1] + rad);
        });
        if (d) [...d.elbows, ...d.endpoints].forEach(([x, y]) => grow(x, y));
      }
      m.forEach(([x, y]) => grow(x, y - 0.01));
      grow(ws[0], ws[1]); grow(ws[2], ws[3]);
      if (frame) { // a margin of 15 % around what moves
        const mx = 0.15 * (b[2] - b[0]), my = 0.15 * (b[3] - b[1]);
        b = [b[0] - mx, b[1] - my, b[2] + mx, b[3] + my];
      }
    }
    const pad = 24;
    const bw = Math.max(b[2] - b[0], 1e-3), bh = Math.max(b[3] - b[1], 1e-3);
    view.scale = Math.min((view.w - 2 * pad) / bw, (view.h - 2 * pad) / bh);
    view.ox = view.w / 2 - view.scale * (b[0] + b[2]) / 2;
    view.oy = view.h / 2 + view.scale * (b[1] + b[3]) / 2;
  }

  const toScreen = (x, y) => [view.ox + x * view.scale, view.oy - y * view.scale];
  const toWorld = (sx, sy) => [(sx - view.ox) / view.scale, (view.oy - sy) / view.scale];

  function drawGrid() {
    const [x0, y1] = toWorld(0, 0), [x1, y0] = toWorld(view.w, view.h);
    const pxPerMm = view.scale * 1e-3;
    const levels = [[0.001, "#efeff2"], [0.01, "#dcdce2"], [0.1, "#c4c4cc"]];
    for (const [step, color] of levels) {
      if (step * view.scale < 4) continue; // too dense to draw
      ctx.strokeStyle = color; ctx.lineWidth = 1;
      ctx.beginPath();
      for (let x = Math.ceil(x0 / step) * step; x <= x1; x += step) {
        const [sx] = toScreen(x, 0); ctx.moveTo(Math.round(sx) + 0.5, 0); ctx.lineTo(Math.round(sx) + 0.5, view.h);
      }
      for (let y = Math.ceil(y0 / step) * step; y <= y1; y += step) {
        const [, sy] = toScreen(0, y); ctx.moveTo(0, Math.round(sy) + 0.5); ctx.lineTo(view.w, Math.round(sy) + 0.5);
      }
      ctx.stroke();
    }
  }

  function poly(points) {
    ctx.beginPath();
    points.forEach((p, i) => { const [sx, sy] = toScreen(p[0], p[1]); i ? ctx.lineTo(sx, sy) : ctx.moveTo(sx, sy); });
    ctx.closePath();
  }

  function drawBodies(f) {
    const s = state.scene;
    s.bodies.forEach((b, i) => {
      const pose = f.bodies[i]; if (!pose) return;
      const c = Math.cos(pose[2]), sn = Math.sin(pose[2]);
      const isSlave = s.slave === i;
      ctx.fillStyle = b.fixed ? "#9a9aa3" : (isSlave ? "rgba(217,72,15,0.75)" : "rgba(54,113,201,0.7)");
      ctx.strokeStyle = b.fixed ? "#6f6f78" : (isSlave ? "#a33208" : "#244e8f");
      ctx.lineWidth = 1.2;
      for (const piece of b.pieces) {
        poly(piece.map(([x, y]) => [pose[0] + c * x - sn * y, pose[1] + sn * x + c * y]));
        ctx.fill(); ctx.stroke();
      }
      if (!b.fixed) { // centre of mass
        const [sx, sy] = toScreen(pose[0], pose[1]);
        ctx.fillStyle = "#fff"; ctx.beginPath(); ctx.arc(sx, sy, 2.5, 0, 2 * Math.PI); ctx.fill();
      }
    });
  }

  function line(a, b) {
    const [ax, ay] = toScreen(a[0], a[1]), [bx, by] = toScreen(b[0], b[1]);
    ctx.beginPath(); ctx.moveTo(ax, ay); ctx.lineTo(bx, by); ctx.stroke();
  }

  function dot(p, r, fill) {
    const [sx, sy] = toScreen(p[0], p[1]);
    ctx.fillStyle = fill; ctx.beginPath(); ctx.arc(sx, sy, r, 0, 2 * Math.PI); ctx.fill();
  }

  function drawDevice(f) {
    const g = state.scene.device, d = f.device;
    if (!g) return;
    const ws = g.workspace;
    ctx.setLineDash([4, 3]); ctx.strokeStyle = "rgba(90,90,100,0.6)"; ctx.lineWidth = 1;
    poly([[ws[0], ws[1]], [ws[2], ws[1]], [ws[2], ws[3]], [ws[0], ws[3]]]); ctx.stroke();
    ctx.setLineDash([]);
    g.motors.forEach((m) => dot(m, 5, "rgba(40,40,48,0.8)"));
    if (!d || !d.valid) return;
    ctx.lineCap = "round";
    // Pantograph 1 (elbows 0, 1 → P1), pantograph 2 (elbows 2, 3 → P2), then the crank P1 → P2.
    const links = [[0, 0, 0], [1, 1, 0], [0, 2, 1], [1, 3, 1]];
    links.forEach(([motor, elbow, end], k) => {
      ctx.strokeStyle = k < 2 ? "rgba(60,60,70,0.55)" : "rgba(120,80,160,0.5)";
      ctx.lineWidth = 4; line(g.motors[motor], d.elbows[elbow]);
      ctx.lineWidth = 2.5; line(d.elbows[elbow], d.endpoints[end]);
    });
    ctx.strokeStyle = "rgba(20,20,20,0.8)"; ctx.lineWidth = 3; line(d.endpoints[0], d.endpoints[1]);
    d.elbows.forEach((e) => dot(e, 2.5, "rgba(40,40,48,0.8)"));
    dot(d.endpoints[0], 4, "#222"); dot(d.endpoints[1], 3, "#7a4fa3");
    ctx.lineCap = "butt";
  }

  function arrow(p, v, color) {
    const [ax, ay] = toScreen(p[0], p[1]);
    const bx = ax + v[0], by = ay - v[1];
    const len = Math.hypot(v[0], v[1]); if (len < 1) return;
    const ux = (bx - ax) / len, uy = (by - ay) / len, h = Math.min(10, len * 0.5);
    const head = () => {
      ctx.beginPath(); ctx.moveTo(bx, by);
      ctx.lineTo(bx - h * ux + 0.5 * h * uy, by - h * uy - 0.5 * h * ux);
      ctx.lineTo(bx - h * ux - 0.5 * h * uy, by - h * uy + 0.5 * h * ux);
      ctx.closePath();
    };
    // A white halo first, so that arrows stay readable over the bodies.
    ctx.strokeStyle = "rgba(255,255,255,0.9)"; ctx.lineWidth = 6; ctx.lineJoin = "round";
    ctx.beginPath(); ctx.moveTo(ax, ay); ctx.lineTo(bx - h * ux, by - h * uy); ctx.stroke();
    head(); ctx.lineWidth = 3; ctx.stroke();
    ctx.strokeStyle = color; ctx.fillStyle = color; ctx.lineWidth = 3;
    ctx.beginPath(); ctx.moveTo(ax, ay); ctx.lineTo(bx - h * ux, by - h * uy); ctx.stroke();
    head(); ctx.fill();
  }

  // Force arrows: 25 px per newton, shortened so that the largest force drawn is at most 110 px.
  let pxPerN = 25;
  function forceLegend() { return `${(10 / pxPerN).toPrecision(2)} N per 10 px`; }
  function drawForces(f) {
    const drive = Math.hypot(f.drive[0], f.drive[1]);
    let fmax = drive;
    for (const c of f.contacts) fmax = Math.max(fmax, Math.abs(c.f_n), Math.abs(c.f_t));
    pxPerN = fmax > 0 ? Math.min(25, 110 / fmax) : 25;
    const PX_PER_N = pxPerN;
    for (const c of f.contacts) {
      // God-object: hollow square on the edge.
      const [gx, gy] = toScreen(c.god_object[0], c.god_object[1]);
      ctx.strokeStyle = "#1971c2"; ctx.lineWidth = 1.5; ctx.strokeRect(gx - 3.5, gy - 3.5, 7, 7);
      arrow(c.point, [c.normal[0] * c.f_n * PX_PER_N, c.normal[1] * c.f_n * PX_PER_N], "#2b8a3e");
      arrow(c.point, [c.tangent[0] * c.f_t * PX_PER_N, c.tangent[1] * c.f_t * PX_PER_N], "#e67700");
      dot(c.point, 3.5, c.state === "colliding" ? "#c92a2a" : "#2b8a3e");
    }
    // The controller's drive on the slave f_cs, at its centre of mass.
    if (f.slave !== null && f.bodies[f.slave]) {
      const p = f.bodies[f.slave];
      arrow(p, [f.drive[0] * PX_PER_N, f.drive[1] * PX_PER_N], "#7048e8");
    }
  }

  // The legend strip along the bottom: colours, then the scale bar (10 mm) and the force scale.
  function drawLegend() {
    ctx.fillStyle = "rgba(255,255,255,0.85)"; ctx.fillRect(0, view.h - 24, view.w, 24);
    const pxPerMm = view.scale * 1e-3;
    const [bx, by] = [view.w - 20 - 10 * pxPerMm, view.h - 7];
    ctx.strokeStyle = "#444"; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.moveTo(bx, by); ctx.lineTo(bx + 10 * pxPerMm, by); ctx.stroke();
    ctx.fillStyle = "#444"; ctx.font = "12px system-ui"; ctx.textAlign = "right";
    const minor = pxPerMm >= 4 ? "1 mm" : (pxPerMm >= 0.4 ? "10 mm" : "100 mm");
    ctx.fillText(`10 mm · grid ${minor} · arrows ${forceLegend()}`, bx - 8, by + 3);
    const items = [["#2b8a3e", "normal force"], ["#e67700", "friction"], ["#7048e8", "drive on slave"],
      ["#1971c2", "god-object"], ["#c2255c", "hand target"], ["rgba(60,60,70,0.8)", "device linkage"]];
    ctx.font = "12px system-ui"; ctx.textAlign = "left";
    let x = 10; const y = view.h - 5;
    for (const [color, text] of items) {
      ctx.fillStyle = color; ctx.fillRect(x, y - 8, 14, 4);
      ctx.fillStyle = "#444"; ctx.fillText(text, x + 18, y - 3);
      x += 18 + ctx.measureText(text).width + 14;
    }
  }

  function drawTarget() {
    const t = state.target; if (!t) return;
    const [sx, sy] = toScreen(t[0], t[1]);
    ctx.strokeStyle = "#c2255c"; ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.arc(sx, sy, 9, 0, 2 * Math.PI); ctx.stroke();
    ctx.beginPath(); ctx.moveTo(sx - 13, sy); ctx.lineTo(sx + 13, sy); ctx.moveTo(sx, sy - 13); ctx.lineTo(sx, sy + 13); ctx.stroke();
    ctx.lineWidth = 2.5; ctx.beginPath(); ctx.moveTo(sx, sy);
    ctx.lineTo(sx + 20 * Math.cos(t[2]), sy - 20 * Math.sin(t[2])); ctx.stroke();
  }

  function drawWorld() {
    const r = resizeCanvas(canvas);
    if (r.w !== view.w || r.h !== view.h) fitView(state.lastFrame);
    ctx.setTransform(view.dpr, 0, 0, view.dpr, 0, 0);
    ctx.fillStyle = "#ffffff"; ctx.fillRect(0, 0, view.w, view.h);
    drawGrid();
    const f = state.lastFrame;
    if (!state.scene || !f) {
      ctx.fillStyle = "#888"; ctx.font = "14px system-ui"; ctx.textAlign = "center";
      ctx.fillText(state.connected ? "waiting for the haptic loop…" : "connecting…", view.w / 2, view.h / 2);
      return;
    }
    drawBodies(f);
    drawDevice(f);
    drawForces(f);
    drawTarget();
    drawLegend();
  }

  // ---------------------------------------------------------------- strip charts
  class StripChart {
    constructor(canvas, title, unit, names, colors, span) {
      Object.assign(this, { canvas, title, unit, names, colors, span });
      this.ctx = canvas.getContext("2d");
      this.clear();
    }
    clear() { this.t = []; this.v = this.names.map(() => []); }
    push(t, values) {
      this.t.push(t); values.forEach((x, i) => this.v[i].push(x));
      while (this.t.length && t - this.t[0] > this.span) { this.t.shift(); this.v.forEach((a) => a.shift()); }
    }
    draw() {
      const r = resizeCanvas(this.canvas), c = this.ctx;
      c.setTransform(r.dpr, 0, 0, r.dpr, 0, 0);
      c.fillStyle = "#fff"; c.fillRect(0, 0, r.w, r.h);
      const L = 44, R = 8, T = 18, B = 16, w = r.w - L - R, h = r.h - T - B;
      let lo = Infinity, hi = -Infinity;
      for (const a of this.v) for (const x of a) if (isFinite(x)) { lo = Math.min(lo, x); hi = Math.max(hi, x); }
      if (!isFinite(lo)) { lo = 0; hi = 1; }
      lo = Math.min(lo, 0); if (hi - lo < 1e-9) hi = lo + 1;
      hi += 0.05 * (hi - lo);
      c.font = "11px system-ui"; c.textAlign = "left"; c.fillStyle = "#333";
      c.fillText(`${this.title} (${this.unit})`, L, 12);
      let lx = L + c.measureText(`${this.title} (${this.unit})`).width + 10;
      this.names.forEach((n, i) => { c.fillStyle = this.colors[i]; c.fillText(n, lx, 12); lx += c.measureText(n).width + 8; });
      c.strokeStyle = "#e3e3e8"; c.lineWidth = 1; c.fillStyle = "#777"; c.textAlign = "right";
      for (let k = 0; k <= 2; k++) {
        const y = T + h - (k / 2) * h, val = lo + (k / 2) * (hi - lo);
        c.beginPath(); c.moveTo(L, Math.round(y) + 0.5); c.lineTo(L + w, Math.round(y) + 0.5); c.stroke();
        c.fillText(axisLabel(val), L - 4, y + 4);
      }
      if (this.t.length < 2) return;
      const t1 = this.t[this.t.length - 1], t0 = t1 - this.span;
      c.textAlign = "right"; c.fillStyle = "#777"; c.fillText(`last ${this.span} s`, L + w, r.h - 3);
      this.v.forEach((a, i) => {
        c.strokeStyle = this.colors[i]; c.lineWidth = 1.5; c.beginPath();
        let pen = false;
        a.forEach((x, j) => {
          if (!isFinite(x)) { pen = false; return; }
          const px = L + ((this.t[j] - t0) / this.span) * w, py = T + h - ((x - lo) / (hi - lo)) * h;
          pen ? c.lineTo(px, py) : c.moveTo(px, py); pen = true;
        });
        c.stroke();
      });
    }
  }

  // An axis value in at most ~6 characters, so it fits the 44 px margin: fixed for ordinary
  // magnitudes, exponent form for tiny or huge ones (0.000121 → "1.2e-4").
  function axisLabel(v) {
    const a = Math.abs(v);
    if (a === 0) return "0";
    if (a >= 1e5 || a < 1e-2) return v.toExponential(1).replace("e+", "e");
    return a >= 100 ? v.toFixed(0) : v.toPrecision(3);
  }

  const charts = [
    new StripChart($("chart-force"), "contact force", "N", ["Fn", "|Ft|"], ["#2b8a3e", "#e67700"], 10),
    new StripChart($("chart-energy"), "energy", "mJ", ["kinetic", "stored", "work", "E_obs"], ["#1971c2", "#2b8a3e", "#868e96", "#c2255c"], 10),
    new StripChart($("chart-timing"), "loop lateness", "µs", ["p50", "p99", "max"], ["#2b8a3e", "#e67700", "#c92a2a"], 10),
  ];

  // ---------------------------------------------------------------- input
  let dragging = false;
  let pendingTarget = null;

  function setTarget(t) {
    state.target = t;
    pendingTarget = t;
  }
  function flushTarget() {
    if (pendingTarget) {
      const [x, y, theta] = pendingTarget;
      send({ type: "set_hand_target", x, y, theta });
      pendingTarget = null;
    }
  }
  function pointerWorld(ev) {
    const r = canvas.getBoundingClientRect();
    return toWorld(ev.clientX - r.left, ev.clientY - r.top);
  }
  canvas.addEventListener("pointerdown", (ev) => {
    if (!state.lastFrame) return;
    dragging = true;
    canvas.setPointerCapture(ev.pointerId);
    const [x, y] = pointerWorld(ev);
    setTarget([x, y, state.target ? state.target[2] : 0]);
  });
  canvas.addEventListener("pointermove", (ev) => {
    if (!dragging) return;
    const [x, y] = pointerWorld(ev);
    setTarget([x, y, state.target ? state.target[2] : 0]);
  });
  const endDrag = () => { dragging = false; flushTarget(); };
  canvas.addEventListener("pointerup", endDrag);
  canvas.addEventListener("pointercancel", endDrag);

  const ROTATE_STEP = 5 * Math.PI / 180;
  function rotate(sign) {
    if (!state.target) return;
    setTarget([state.target[0], state.target[1], state.target[2] + sign * ROTATE_STEP]);
  }
  canvas.addEventListener("wheel", (ev) => { ev.preventDefault(); rotate(ev.deltaY < 0 ? 1 : -1); }, { passive: false });
  window.addEventListener("keydown", (ev) => {
    if (ev.target && ev.target.tagName === "SELECT") return;
    if (ev.key === "q" || ev.key === "Q") rotate(1);
    if (ev.key === "e" || ev.key === "E") rotate(-1);
  });

  $("btn-pause").onclick = () => send({ type: state.lastFrame && state.lastFrame.paused ? "resume" : "pause" });
  $("btn-reset").onclick = () => send({ type: "reset" });
  // A first-visit hint: what to do with the page, until the person says they have seen it.
  (() => {
    let seen = false;
    try { seen = localStorage.getItem("haptic2d.hint-seen") === "1"; } catch (e) { /* storage blocked */ }
    const hint = $("first-visit");
    hint.hidden = seen;
    $("btn-hint-ok").onclick = () => {
      hint.hidden = true;
      try { localStorage.setItem("haptic2d.hint-seen", "1"); } catch (e) { /* storage blocked */ }
    };
  })();
  window.addEventListener("resize", () => fitView(state.lastFrame));

  // ---------------------------------------------------------------- render loop
  function render() {
    flushTarget(); // at most one target command per animation frame
    drawWorld();
    charts.forEach((c) => c.draw());
    requestAnimationFrame(render);
  }

  window.__haptic2d = {
    get lastFrame() { return state.lastFrame; },
    get framesReceived() { return state.framesReceived; },
    get framesForScene() { return state.framesForScene; },
    get scene() { return state.scene; },
    get welcome() { return state.welcome; },
    get connected() { return state.connected; },
    get errors() { return state.errors.slice(); },
    get acks() { return state.acks.slice(); },
    get target() { return state.target && state.target.slice(); },
    get commandsSent() { return state.commandsSent; },
    get study() { return study.view; },
    get answersSent() { return study.sent.slice(); },
    // The study phases the page saw, in order ({trial, phase, interval}), for tests.
    get studyTransitions() { return study.transitions.slice(); },
    send,
    // World point (m) → viewport pixel, for tests that drive the pointer.
    worldToClient(x, y) {
      const r = canvas.getBoundingClientRect();
      const [sx, sy] = toScreen(x, y);
      return { x: r.left + sx, y: r.top + sy };
    },
    clientToWorld(cx, cy) {
      const r = canvas.getBoundingClientRect();
      return toWorld(cx - r.left, cy - r.top);
    },
  };

  fitView(null);
  connect();
  requestAnimationFrame(render);
})();
