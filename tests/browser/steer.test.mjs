// Steering from the page: a leash on a tagged activity, alarms, and aborting the mission.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { browser, choose, examples, open, position, shot, start } from "./harness.mjs";

let station, chromium;

before(async () => {
  station = await start(["gcs", examples(), "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
});

const moved = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);

/// Waits `ms` of real time; resolves to how far `name` moved meanwhile.
async function travel(page, name, ms) {
  const from = await position(page, name);
  await page.waitForTimeout(ms);
  return moved(from, await position(page, name));
}

test("PAUSE on a tagged activity holds its drone; RESUME lets it go on", async () => {
  const page = await open(chromium, station);
  await choose(page, "drills/patrol.mission");
  await page.fill("#speed", "10");
  await page.click("#fly");
  await page.waitForFunction(() => window.aviary.model.activities.get("FlyCircle|C1|scout")?.running === 1, null, { timeout: 60000 });
  await page.waitForTimeout(500);
  await page.fill("#leash-tag", "FlyCircle-C1");
  await page.fill("#leash-action", "PAUSE");
  await page.click("#leash-form button");
  await page.waitForFunction(() => [...document.querySelectorAll("#log li")].some((li) => li.textContent.includes("leash FlyCircle-C1 PAUSE")));
  await page.waitForTimeout(300); // the call in flight is held
  const held = await travel(page, "scout", 1500);
  const carrier = await travel(page, "carrier", 1000);
  assert.ok(held < 0.5, `scout holds while paused (moved ${held.toFixed(2)} m in 15 s of mission)`);
  assert.ok(carrier > 20, `the carrier goes on (moved ${carrier.toFixed(1)} m)`);
  await page.waitForFunction(() => document.querySelector("#tree .node[data-status=paused]") !== null);
  await shot(page, "leash-paused");
  await page.fill("#leash-action", "RESUME");
  await page.click("#leash-form button");
  const going = await travel(page, "scout", 1000);
  assert.ok(going > 20, `scout goes on after RESUME (moved ${going.toFixed(1)} m)`);
  await page.waitForFunction(() => window.aviary.model.status === "ok", null, { timeout: 120000 });
  const circle = await page.evaluate(() => window.aviary.model.activities.get("FlyCircle|C1|scout"));
  assert.equal(circle.done, 1, "the circle ends ok");
});

test("hold one drone, then send it home, from the fleet grid: the others carry on", async () => {
  const page = await open(chromium, station);
  await choose(page, "drills/patrol.mission");
  await page.fill("#speed", "10");
  await page.click("#fly");
  await page.waitForFunction(() => window.aviary.model.activities.get("FlyCircle|C1|scout")?.running === 1, null, { timeout: 60000 });
  const row = (drone) => `#fleet tr[data-drone="${drone}"]`;
  await page.click(`${row("scout")} button[data-action="hold"]`);
  await page.waitForFunction(() => window.aviary.model.drones.get("scout").held);
  await page.waitForTimeout(300);
  const held = await travel(page, "scout", 1500);
  const carrier = await travel(page, "carrier", 1000);
  assert.ok(held < 0.5, `scout holds (moved ${held.toFixed(2)} m)`);
  assert.ok(carrier > 20, `the carrier carries on (moved ${carrier.toFixed(1)} m)`);
  await page.waitForFunction(() => document.querySelector('#fleet tr[data-drone="scout"]').classList.contains("held"));
  await shot(page, "drone-held");
  await page.click(`${row("scout")} button[data-action="resume"]`);
  assert.ok((await travel(page, "scout", 1000)) > 20, "scout goes on after resume");
  await page.click(`${row("scout")} button[data-action="home"]`);
  await page.waitForSelector("#confirm-dialog[open]");
  await page.click('#confirm-dialog button[value="ok"]');
  await page.waitForFunction(() => window.aviary.model.drones.get("scout").withdrawn);
  await page.waitForFunction(() => document.getElementById("status").textContent !== "running", null, { timeout: 120000 });
  const end = await page.evaluate(() => ({
    status: window.aviary.model.status,
    log: [...document.querySelectorAll("#log li")].map((li) => li.textContent),
    scout: window.aviary.model.drones.get("scout"),
    circle: window.aviary.model.activities.get("FlyCircle|C1|scout"),
    carrier: window.aviary.model.activities.get("ReturnHome||carrier"),
  }));
  assert.equal(end.status, "ok", "the mission goes on with the rest and ends ok");
  for (const action of ["hold scout", "resume scout", "return_home scout"]) {
    assert.ok(end.log.some((l) => l.includes(`operator: ${action}`)), `the trace has the operator's ${action}: ${end.log.slice(-20)}`);
  }
  assert.equal(end.circle.aborted, 1, "sending scout home aborted its circle");
  assert.equal(end.carrier.done, 1, "the carrier flew its whole round");
  assert.equal(end.scout.state, "Landed");
  assert.ok(moved(end.scout.pos, [0, 0, 0]) < 3, `scout is home: ${end.scout.pos}`);
  await shot(page, "drone-home");
});

test("a fault raises its alarm; aborting brings the fleet home", async () => {
  const page = await open(chromium, station);
  await choose(page, "faults/motor_failure.mission");
  await page.fill("#speed", "8");
  await page.click("#fly");
  await page.waitForSelector('.alarm[data-kind="MotorFailure"]', { timeout: 60000 });
  const text = await page.textContent('.alarm[data-kind="MotorFailure"]');
  assert.match(text, /MotorFailure on scout/);
  await shot(page, "alarm");
  await page.click('.alarm[data-kind="MotorFailure"] button');
  assert.equal(await page.locator('.alarm[data-kind="MotorFailure"]').count(), 0, "acknowledged, it goes");
  await page.click("#abort");
  await page.waitForSelector("#confirm-dialog[open]");
  await page.click('#confirm-dialog button[value="ok"]');
  await page.waitForFunction(() => document.getElementById("status").textContent === "aborted", null, { timeout: 120000 });
  const fleet = await page.evaluate(() => [...window.aviary.model.drones.values()].map((d) => ({ name: d.name, state: d.state, pos: d.pos })));
  const homes = await page.evaluate(() => Object.fromEntries(window.aviary.about.map.drones.map((d) => [d.name, d.home])));
  for (const d of fleet) {
    if (d.name === "scout") continue; // its motor failed: it came down where it was
    assert.equal(d.state, "Landed", `${d.name} landed`);
    assert.ok(moved(d.pos, homes[d.name]) < 3, `${d.name} is home: ${d.pos} vs ${homes[d.name]}`);
  }
  await shot(page, "aborted");
});
