// The ground station as an operator uses it: `aviary gcs` on a copy of the examples, the
// page in headless Chromium.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { spawnSync } from "node:child_process";
import { copyFileSync, readFileSync } from "node:fs";
import { join } from "node:path";
import { AVIARY, browser, choose, examples, open, shot, start } from "./harness.mjs";

let station, chromium, dir;

before(async () => {
  dir = examples();
  station = await start(["gcs", dir, "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
});

test("the paper's mission flies from the page: 7 drones move on the map and the tree ends done", async () => {
  const page = await open(chromium, station);
  await page.waitForSelector("#mission-file option", { state: "attached" });
  assert.equal(await page.inputValue("#mission-file"), "search_and_rescue.mission");
  await page.waitForSelector("#check-summary.good");
  await shot(page, "checked");
  await page.fill("#speed", "40");
  await page.click("#fly");
  await page.waitForFunction(() => window.aviary.model.status === "running");
  // Seven drones on the map, each moving away from its home.
  await page.waitForFunction(() => window.aviary.model.drones.size === 7);
  const homes = await page.evaluate(() => Object.fromEntries([...window.aviary.model.drones].map(([n, d]) => [n, d.pos])));
  await page.waitForFunction(() => [...window.aviary.model.drones.values()].filter((d) => d.trail.length > 5).length >= 3);
  await page.waitForFunction(() => document.querySelector('#tree .node[data-status="running"]') !== null);
  // Well into the mission (the search has started), and the page drawn since.
  await page.waitForFunction(() => window.aviary.model.t > 120);
  await page.waitForTimeout(400);
  const shown = await page.evaluate(() => ({
    clock: document.getElementById("clock").textContent,
    activities: [...document.querySelectorAll("#fleet tbody tr td:nth-child(7)")].map((td) => td.textContent),
  }));
  assert.match(shown.clock, /^t = (1[2-9]\d|[2-9]\d\d)\.\d s$/, "the clock goes with the mission");
  assert.ok(shown.activities.filter((a) => a !== "–").length >= 3, `running activities in the grid: ${shown.activities}`);
  // The video drones stream while they circle: the grid says so.
  assert.ok(shown.activities.some((a) => a.endsWith(" · streaming")), `streaming in the grid: ${shown.activities}`);
  await shot(page, "flying");
  // As the operator sees it: the badge, not the model behind it.
  await page.waitForFunction(() => !["running", "paused"].includes(document.getElementById("status").textContent), null, { timeout: 240000 });
  const end = await page.evaluate(() => ({
    status: window.aviary.model.status,
    badge: document.getElementById("status").textContent,
    moved: [...window.aviary.model.drones.values()].filter((d) => d.trail.length > 2).length,
    done: document.querySelectorAll('#tree .node[data-status="done"]').length,
    running: document.querySelectorAll('#tree .node[data-status="running"]').length,
  }));
  assert.equal(end.status, "ok");
  assert.equal(end.badge, "ok");
  assert.equal(end.moved, 7, "every drone moved");
  assert.ok(end.done > 10, `blocks and activities done in the tree: ${end.done}`);
  assert.equal(end.running, 0, "nothing is left running");
  // Every drone is down at the end, in the grid and in /api/state: the trace ends with
  // their state at the end, not the last periodic sample (one was still "Landing").
  const states = await page.evaluate(() => [...document.querySelectorAll("#fleet tbody tr td:nth-child(2)")].map((td) => td.textContent));
  assert.deepEqual(states, Array(7).fill("Landed"), `the grid at the end: ${states}`);
  const api = await page.evaluate(async (token) => (await fetch("/api/state", { headers: { Authorization: "Bearer " + token } })).json(), station.token);
  const down = api.drones.map((d) => d.state);
  assert.deepEqual(down, Array(7).fill("Landed"), `/api/state at the end: ${JSON.stringify(api.drones)}`);
  await page.waitForTimeout(300);
  await shot(page, "done");
  // The flight's trace is in the folder, whole, with telemetry to replay it.
  const shownTrace = (await page.textContent("#trace-file")).replace(/^trace /, "");
  assert.match(shownTrace, /^traces\/search_and_rescue-\d{4}-\d\d-\d\dT\d\d-\d\d-\d\dZ(-\d+)?\.jsonl$/);
  const lines = readFileSync(join(dir, shownTrace), "utf8").trim().split("\n").map((l) => JSON.parse(l));
  assert.equal(lines[0].event, "mission_start");
  assert.deepEqual([lines.at(-1).event, lines.at(-1).status], ["mission_end", "ok"]);
  assert.ok(lines.filter((e) => e.event === "telemetry").length > 7 * 400, "4 samples a second per drone");
  assert.deepEqual(page.foreign, [], "the page loaded nothing from elsewhere");
  assert.ok(homes, "positions were known");
});

test("an edited mission with an error shows the diagnostic on its line and cannot fly", async () => {
  const page = await open(chromium, station);
  await page.waitForSelector("#check-summary.good");
  const before = await page.evaluate(() => window.aviary.editor.files.mission.text);
  const lines = before.split("\n");
  const at = lines.findIndex((l) => l.includes("FlyTo WITH"));
  lines[at] = lines[at].replace(/FlyTo WITH \w+/, "FlyTo WITH Nowhere");
  const text = lines.join("\n");
  // The operator selects the whole text and pastes the edited mission over it.
  await page.click(".editor-file[data-file=mission] .cm-content");
  await page.keyboard.press("Control+A");
  await page.keyboard.insertText(text);
  assert.equal(await page.evaluate(() => window.aviary.editor.files.mission.text), text);
  await page.click("#check");
  await page.waitForSelector("#diagnostics li.error");
  const d = await page.evaluate(() => {
    const li = document.querySelector("#diagnostics li.error");
    return { code: li.dataset.code, line: Number(li.dataset.line), text: li.textContent,
      fly: document.getElementById("fly").disabled };
  });
  // A click on the diagnostic goes to its line, which the gutter marks as an error.
  await page.click("#diagnostics li.error");
  await page.waitForSelector(".editor-file[data-file=mission] .cm-gutter-lint .cm-lint-marker-error");
  const marked = await page.evaluate(() => {
    const box = document.querySelector(".editor-file[data-file=mission]");
    const active = box.querySelector(".cm-lineNumbers .cm-activeLineGutter");
    const top = active.getBoundingClientRect().top;
    const beside = [...box.querySelectorAll(".cm-gutter-lint .cm-gutterElement")]
      .find((e) => Math.abs(e.getBoundingClientRect().top - top) < 2);
    return { line: Number(active.textContent), error: !!beside?.querySelector(".cm-lint-marker-error"),
      selected: window.aviary.editor.view.state.sliceDoc(window.aviary.editor.view.state.selection.main.from,
        window.aviary.editor.view.state.selection.main.to) };
  });
  d.gutter = marked.error;
  assert.equal(marked.line, at + 1, "the click went to the diagnostic's line");
  assert.match(marked.selected, /Nowhere/, "and selected what it is about");
  assert.equal(d.code, "E103");
  assert.equal(d.line, at + 1, "the diagnostic is on the edited line");
  assert.match(d.text, /unknown place `Nowhere`/);
  assert.ok(d.gutter, "the gutter marks the line");
  assert.ok(d.fly, "Fly is disabled");
  await shot(page, "diagnostic");
  // Asked to fly all the same (as a script could), the station refuses.
  const refused = await page.evaluate(async ({ token, text }) => {
    const r = await fetch("/api/station/fly", { method: "POST", headers: { "Content-Type": "application/json", Authorization: "Bearer " + token },
      body: JSON.stringify({ mission: { path: "search_and_rescue.mission", text }, world: { path: "search_and_rescue.world.toml", text: "" }, speed: 10 }) });
    return { status: r.status, body: await r.json() };
  }, { token: station.token, text: lines.join("\n") });
  assert.equal(refused.status, 409);
  assert.match(refused.body.error, /cannot fly/);
  // Nothing was saved: the file on disk is as it was.
  assert.equal(readFileSync(join(dir, "search_and_rescue.mission"), "utf8"), before);
});

test("control needs the token and other sites are refused", async () => {
  const fly = await fetch(station.url + "/api/station/fly", { method: "POST", headers: { "Content-Type": "application/json" }, body: "{}" });
  assert.equal(fly.status, 401);
  const save = await fetch(station.url + "/api/station/save", { method: "POST", headers: { "Content-Type": "application/json", Authorization: "Bearer nope" }, body: "{}" });
  assert.equal(save.status, 401);
  const cross = await fetch(station.url + "/api/station/files", { headers: { Origin: "http://evil.example" } });
  assert.equal(cross.status, 403);
  // From a page of another site, in the browser: the request is refused and unreadable.
  const page = await open(chromium, station, { token: false });
  const other = await page.context().newPage();
  await other.route("http://evil.example/", (r) => r.fulfill({ body: "<html><body>evil</body></html>", contentType: "text/html" }));
  await other.goto("http://evil.example/");
  const seen = await other.evaluate(async (url) => {
    try {
      const r = await fetch(url + "/api/station/files");
      return `read ${r.status}`;
    } catch (e) {
      return "refused";
    }
  }, station.url);
  assert.equal(seen, "refused");
  const socket = await other.evaluate((url) => new Promise((resolve) => {
    const ws = new WebSocket(url.replace("http", "ws") + "/api/events", ["aviary"]);
    ws.onopen = () => resolve("open");
    ws.onerror = () => resolve("refused");
  }), station.url);
  assert.equal(socket, "refused");
});

test("a mission with no world beside it is checked without one, as aviary check does, and notes are counted as notes", async () => {
  // A mission alone in the folder: `aviary check` takes no world and says what it could not check.
  copyFileSync(join(dir, "search_and_rescue.mission"), join(dir, "alone.mission"));
  const cli = (args) => spawnSync(AVIARY, ["check", ...args], { cwd: dir, encoding: "utf8" });
  const alone = cli(["alone.mission"]);
  assert.equal(alone.status, 0, alone.stderr);
  assert.match(alone.stdout, /alone\.mission: ok \(2 notes\)/);
  const page = await open(chromium, station);
  await page.waitForSelector("#check-summary.good");
  // The paper's mission with its world: the notes of `aviary check`, not warnings.
  const paper = cli(["search_and_rescue.mission"]).stdout.match(/: ok \((.*)\)/)[1];
  assert.equal(await page.textContent("#check-summary"), `no errors, ${paper}: ready to fly`);
  await page.selectOption("#mission-file", "alone.mission");
  await page.waitForFunction(() => /choose a world/.test(document.getElementById("check-summary").textContent));
  assert.equal(await page.inputValue("#world-file"), "", "no world chosen");
  assert.equal(await page.textContent("#check-summary"), "no errors, 2 notes: choose a world to fly");
  assert.ok(await page.isDisabled("#fly"), "it cannot fly without a world");
  const codes = await page.evaluate(() => window.aviary.checked.diagnostics.map((d) => d.code));
  assert.deepEqual(codes.sort(), ["N301", "N302"], "the notes aviary check gives");
  // Choosing a world checks against it, and it may fly.
  await page.selectOption("#world-file", "search_and_rescue.world.toml");
  await page.waitForSelector("#check-summary.good");
  await page.waitForFunction(() => /ready to fly/.test(document.getElementById("check-summary").textContent));
  assert.ok(!(await page.isDisabled("#fly")));
  assert.deepEqual(page.foreign, [], "nothing from elsewhere");
});

test("the grid names the capability a drone works in, and a page opened after the run shows its times and heights", async () => {
  const page = await open(chromium, station);
  await choose(page, "parcel_delivery.mission");
  await page.fill("#speed", "20");
  await page.click("#fly");
  // courier2 flies to the clinic inside Deliver: its FlyTo's TakeOff ends, and the grid
  // still names what it does (it showed "–" between the TakeOff and the end of Deliver).
  await page.waitForFunction(() => window.aviary.model.mission === "Parcel_Delivery" && window.aviary.model.t > 12);
  await page.waitForTimeout(300);
  const working = await page.evaluate(() => {
    const row = [...document.querySelectorAll("#fleet tbody tr")].find((r) => r.cells[0].textContent.includes("courier2"));
    return row.cells[6].textContent;
  });
  assert.equal(working, "Deliver › FlyTo");
  await page.waitForFunction(() => window.aviary.model.mission === "Parcel_Delivery" && window.aviary.model.status === "ok", null, { timeout: 120000 });
  // A page opened after the run: the state at its end, then every event since the start.
  const late = await open(chromium, station);
  await late.waitForFunction(() => window.aviary.model.mission === "Parcel_Delivery" && window.aviary.model.status === "ok" && window.aviary.model.alarms.length > 0);
  await late.waitForTimeout(300);
  const seen = await late.evaluate(() => ({
    alarms: window.aviary.model.alarms.map((a) => [a.kind, a.who, a.t]),
    shown: [...document.querySelectorAll("#alarms .alarm span")].map((s) => s.textContent),
    courier1: window.aviary.model.drones.get("courier1").pos,
    height: [...document.querySelectorAll("#fleet tbody tr")].find((r) => r.cells[0].textContent.includes("courier1")).cells[3].textContent,
  }));
  // The motor failure at 30 s is shown at 30 s, not at the end of the run.
  assert.deepEqual(seen.alarms.find((a) => a[0] === "MotorFailure"), ["MotorFailure", "courier1", 30]);
  assert.ok(seen.shown.some((s) => s.startsWith("t = 30.0 s")), `alarms as shown: ${seen.shown}`);
  // courier1 landed in a field: on the ground, not at the height of its last command.
  assert.ok(seen.courier1[2] < 1, `courier1 at ${seen.courier1}`);
  assert.match(seen.height, /^0\.\d m$/, `its height in the grid: ${seen.height}`);
  await shot(late, "opened-after-the-run");
});
