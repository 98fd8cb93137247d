// Flying MAVLink drones from the page, as `aviary run` flies such a world: the fleet
// served by the real `aviary vehicles` on loopback (ArduCopter-like vehicles, here at 10
// times real time so that the test is short), each drone its own MAVLink system.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { browser, mavlinkPatrol, open, shot, start } from "./harness.mjs";

let station, chromium, vehicles, dir;

before(async () => {
  ({ dir, vehicles } = await mavlinkPatrol("aviary-gcs-mavlink-"));
  station = await start(["gcs", dir, "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
  vehicles?.kill("SIGTERM");
});

test("MAVLink drones fly from the page: they move on the map and the run ends ok", async () => {
  const page = await open(chromium, station);
  await page.waitForSelector("#mission-file option", { state: "attached" });
  await page.selectOption("#mission-file", "patrol.mission");
  await page.waitForSelector("#check-summary.good");
  // Real drones fly in real time: no speed is given (the vehicles themselves run fast).
  await page.fill("#speed", "");
  await page.click("#fly");
  await page.waitForFunction(() => window.aviary.model.status === "running", null, { timeout: 60000 });
  // The MAVLink drone's telemetry reaches the map: it leaves its home for the tower.
  await page.waitForFunction(() => {
    const s = window.aviary.model.drones.get("scout");
    return s && s.pos && s.pos[1] > 100;
  }, null, { timeout: 120000 });
  await shot(page, "mavlink");
  await page.waitForFunction(() => !["running", "paused"].includes(document.getElementById("status").textContent), null, { timeout: 240000 });
  const end = await page.evaluate(() => ({
    badge: document.getElementById("status").textContent,
    scout: window.aviary.model.drones.get("scout").trail.length,
    carrier: window.aviary.model.drones.get("carrier").trail.length,
  }));
  assert.equal(end.badge, "ok");
  assert.ok(end.scout > 10 && end.carrier > 10, `both moved: ${JSON.stringify(end)}`);
  // The flight's trace shows the scout's calls, flown over MAVLink to their ends.
  const shownTrace = (await page.textContent("#trace-file")).replace(/^trace /, "");
  // The file is written before the page hears each event, so it is whole by now; read
  // it as the page's t was, to say so if it is not.
  const text = readFileSync(join(dir, shownTrace), "utf8");
  const pageT = await page.evaluate(() => window.aviary.model.t);
  assert.ok(text.endsWith("\n") && text.includes('"event":"mission_end"'),
    `the trace ends with mission_end when the page says the run ended at t = ${pageT}: ...${text.slice(-300)}`);
  const lines = text.trim().split("\n").map((l) => JSON.parse(l));
  const circled = lines.find((e) => e.event === "api_done" && e.actor === "scout" && e.function === "Orbit");
  assert.ok(circled && circled.status === "ok", "the scout's orbit, flown by the MAVLink vehicle, ended ok");
  assert.deepEqual([lines.at(-1).event, lines.at(-1).status], ["mission_end", "ok"]);
  assert.deepEqual(page.foreign, [], "the page loaded nothing from elsewhere");
});
