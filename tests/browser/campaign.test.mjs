// A campaign from the station: the open mission flown on many seeds, its success rate
// shown in the page and its report saved, the same as `aviary test` says.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { spawnSync } from "node:child_process";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { AVIARY, browser, examples, open, shot, start } from "./harness.mjs";

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

test("the station runs a campaign on the open mission and saves its report", async () => {
  const page = await open(chromium, station);
  await page.waitForSelector("#check-summary.good");
  await page.selectOption("#mission-file", "drills/patrol.mission");
  await page.waitForFunction(() => window.aviary.editor.files.world.path === "drills/patrol.world.toml");
  await page.waitForSelector("#check-summary.good");
  await page.fill("#campaign-runs", "20");
  const [download] = await Promise.all([
    page.waitForEvent("download", { timeout: 120000 }),
    page.click("#campaign"),
  ]);
  assert.equal(download.suggestedFilename(), "patrol-campaign.html");
  const shown = await page.textContent("#campaign-summary");
  // What the command line says of the same mission, world and seeds.
  // (It exits 1 when a run fails: the output is what is compared.)
  const cli = spawnSync(
    AVIARY,
    ["test", "drills/patrol.mission", "--world", "drills/patrol.world.toml", "--runs", "20", "--seed", "0"],
    { cwd: dir, encoding: "utf8" },
  ).stdout.split("\n").find((l) => l.startsWith("success:"));
  assert.equal(shown, cli, "the page's success line is aviary test's");
  assert.match(shown, /^success: \d+ of 20 runs/);
  const saved = join(dir, "saved-campaign.html");
  await download.saveAs(saved);
  const html = readFileSync(saved, "utf8");
  assert.match(html, /^<!doctype html>/i);
  assert.ok(html.includes("Campaign of"), "the campaign's title");
  assert.ok((html.match(/<svg/g) || []).length >= 3, "its plots");
  assert.ok(!/<script/i.test(html), "no script");
  await shot(page, "campaign");
  assert.deepEqual(page.foreign, [], "nothing from elsewhere");
});
