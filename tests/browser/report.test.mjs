// The report: one HTML file, opened offline in the browser.

import { test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdtempSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { AVIARY, ROOT, browser, shot } from "./harness.mjs";

test("the report of the paper's mission opens offline and holds every drone's track and plots", async () => {
  const dir = mkdtempSync(join(tmpdir(), "aviary-report-"));
  const trace = join(dir, "paper.jsonl");
  const report = join(dir, "paper.html");
  execFileSync(AVIARY, ["run", "examples/search_and_rescue.mission", "--quiet", "--trace", trace, "--telemetry-hz", "2"], { cwd: ROOT });
  execFileSync(AVIARY, ["report", trace, "--world", "examples/search_and_rescue.world.toml", "-o", report], { cwd: ROOT });
  const chromium = await browser();
  try {
    const context = await chromium.newContext({ viewport: { width: 1100, height: 1400 }, offline: true });
    const page = await context.newPage();
    const asked = [];
    page.on("request", (r) => { if (!r.url().startsWith("file://")) asked.push(r.url()); });
    await page.goto("file://" + report);
    const seen = await page.evaluate(() => ({
      title: document.querySelector("h1").textContent,
      rows: [...document.querySelectorAll("table:first-of-type tr td:first-child")].map((td) => td.textContent),
      legend: document.querySelector(".map svg").textContent,
      tracks: document.querySelectorAll(".map svg polyline").length,
      drones: [...document.querySelectorAll("section.drone")].map((s) => ({ name: s.querySelector("h3").textContent, plots: s.querySelectorAll("svg").length, lines: s.querySelectorAll("svg polyline").length })),
      scripts: document.scripts.length,
    }));
    const names = ["beacon_drone1", "beacon_drone2", "flir_drone1", "flir_drone2", "sensor_drone", "video_drone1", "video_drone2"];
    assert.match(seen.title, /Search_and_Rescue — ok/);
    assert.deepEqual(seen.rows, names);
    for (const n of names) assert.ok(seen.legend.includes(n), `the map's legend names ${n}`);
    assert.ok(seen.tracks >= 7, `a track per drone: ${seen.tracks} lines`);
    assert.deepEqual(seen.drones.map((d) => d.name), names);
    for (const d of seen.drones) {
      assert.equal(d.plots, 3, `${d.name}: altitude, speed, battery`);
      assert.ok(d.lines >= 3, `${d.name}: a line in each plot`);
    }
    assert.equal(seen.scripts, 0, "no script");
    assert.deepEqual(asked, [], "nothing asked of the network");
    await shot(page, "report");
  } finally {
    await chromium.close();
  }
});
