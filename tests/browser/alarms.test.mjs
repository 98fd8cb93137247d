// Alarms the page raises from what the trace says as data: a separation timeout by the
// exception's `cause` (not by the words of its reason), in orange, and a drone fault by
// the language's own list of them (`/assets/js/builtins.js`).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { browser, choose, examples, open, shot, start } from "./harness.mjs";

let station, chromium;

before(async () => {
  station = await start(["gcs", examples(), "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
});

test("a flight held back by separation until it timed out raises an orange alarm", async () => {
  const page = await open(chromium, station);
  await choose(page, "drills/crowd.mission");
  await page.fill("#speed", "10");
  await page.click("#fly");
  await page.waitForSelector('.alarm[data-kind="separation"]', { timeout: 60000 });
  const alarm = await page.evaluate(() => window.aviary.model.alarms.find((a) => a.kind === "separation"));
  assert.equal(alarm.who, "second");
  assert.equal(alarm.severe, false, "orange: the drone hovers, clear of the other");
  assert.match(alarm.text, /Timeout on second: second waited 3 s for first to make room/);
  const faults = await page.evaluate(async () => (await import("/assets/js/builtins.js")).DRONE_FAULTS.size);
  assert.equal(faults, 6, "the drone faults the language lists");
  await shot(page, "separation-alarm");
});
