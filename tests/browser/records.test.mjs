// A newcomer's whole path in one page (`aviary gcs`): fly a mission, then replay its
// record and save its report, without leaving the station or using the command line.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { browser, examples, open, shot, start } from "./harness.mjs";

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

test("a flight's record replays in the page and its report is saved from it", async () => {
  const page = await open(chromium, station);
  await page.waitForSelector("#check-summary.good");
  await page.selectOption("#mission-file", "drills/patrol.mission");
  await page.waitForFunction(() => window.aviary.editor.files.world.path === "drills/patrol.world.toml");
  await page.waitForSelector("#check-summary.good");
  await page.fill("#speed", "100");
  await page.click("#fly");
  await page.waitForFunction(() => window.aviary.model.status === "ok", null, { timeout: 120000 });
  // The flight's trace is the record chosen, once the list is read again.
  const shownTrace = (await page.textContent("#trace-file")).replace(/^trace /, "");
  await page.waitForFunction((t) => document.getElementById("trace-list").value === t, shownTrace);
  const events = readFileSync(join(dir, shownTrace), "utf8").trim().split("\n").map((l) => JSON.parse(l));

  // Another world chosen above does not change what the record is drawn on: the trace
  // names the world it was flown in.
  await page.selectOption("#world-file", "search_and_rescue.world.toml");
  // Report: one HTML file, saved as a download, with every drone's track and plots.
  const [download] = await Promise.all([page.waitForEvent("download"), page.click("#report-trace")]);
  assert.match(download.suggestedFilename(), /^patrol-.*\.html$/);
  const saved = join(dir, "saved-report.html");
  await download.saveAs(saved);
  const html = readFileSync(saved, "utf8");
  assert.match(html, /^<!DOCTYPE html>/i);
  for (const d of ["scout", "carrier", "spare"]) assert.ok(html.includes(d), `${d} in the report`);
  assert.ok((html.match(/<svg/g) || []).length >= 4, "a map and plots");
  assert.ok(!/<script/i.test(html), "no script");

  assert.ok(html.includes("Tower") && html.includes("Bridge"), "drawn on the patrol's world, with its places");
  assert.ok(!html.includes("BuildingA") && !html.includes("Facility"), "not on the world chosen above");

  // Replay: the same page plays the record back on its world, and leads back.
  await page.click("#replay-trace");
  // The page loads anew for the replay: until it has, there is no `window.aviary`.
  await page.waitForFunction(() => window.aviary && window.aviary.replay && window.aviary.replay.end > 0);
  const end = await page.evaluate(() => window.aviary.replay.end);
  assert.equal(end, events.at(-1).t, "the scrubber spans the whole flight");
  const t = Math.round(end / 2);
  await page.evaluate((time) => {
    const scrub = document.getElementById("scrub");
    scrub.value = String(time);
    scrub.dispatchEvent(new Event("input"));
  }, t);
  await page.waitForTimeout(300);
  const shown = await page.evaluate(() => Object.fromEntries([...window.aviary.model.drones].map(([n, d]) => [n, d.pos])));
  const want = {};
  for (const e of events) if (e.event === "telemetry" && e.t <= t) want[e.actor] = e.position;
  assert.ok(Object.keys(want).length === 3, "telemetry of the three drones");
  for (const [name, p] of Object.entries(want)) assert.deepEqual(shown[name], p, `${name} at t = ${t}`);
  assert.ok(await page.evaluate(() => window.aviary.map.world.getLayers().length > 3), "the world is drawn");
  // Only the drones that flew: none of the world chosen above appears as an "unknown" drone.
  const drones = await page.evaluate(() => [...window.aviary.model.drones.keys()].sort());
  assert.deepEqual(drones, ["carrier", "scout", "spare"]);
  assert.equal(await page.isVisible("#leave-replay"), true);
  await shot(page, "records");
  assert.deepEqual(page.foreign, [], "nothing from elsewhere");
});
