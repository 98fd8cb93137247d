// Replay: a trace recorded by `aviary run --trace`, played back in the page.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdtempSync, readFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { AVIARY, ROOT, browser, open, shot, start } from "./harness.mjs";

let station, chromium, events;

before(async () => {
  const trace = join(mkdtempSync(join(tmpdir(), "aviary-replay-")), "paper.jsonl");
  execFileSync(AVIARY, ["run", "examples/search_and_rescue.mission", "--quiet", "--trace", trace, "--telemetry-hz", "2"], { cwd: ROOT });
  events = readFileSync(trace, "utf8").split("\n").filter(Boolean).map((l) => JSON.parse(l));
  station = await start(["replay", trace, "--world", join(ROOT, "examples/search_and_rescue.world.toml"), "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
});

/// Each drone's last telemetry at or before `t`, as the trace holds it.
function positionsAt(t) {
  const at = {};
  for (const e of events) if (e.event === "telemetry" && e.t <= t) at[e.actor] = e.position;
  return at;
}

test("replay scrubbed to a time shows the positions the trace holds for that time", async () => {
  const page = await open(chromium, station);
  await page.waitForFunction(() => window.aviary.replay && window.aviary.replay.end > 0);
  const end = await page.evaluate(() => window.aviary.replay.end);
  assert.equal(end, events[events.length - 1].t, "the scrubber spans the whole mission");
  for (const t of [60.3, 200, 35.5, 470]) {
    await page.evaluate((time) => {
      const scrub = document.getElementById("scrub");
      scrub.value = String(time);
      scrub.dispatchEvent(new Event("input"));
    }, t);
    await page.waitForTimeout(250);
    const shown = await page.evaluate(() => Object.fromEntries([...window.aviary.model.drones].map(([n, d]) => [n, d.pos])));
    const want = positionsAt(t);
    assert.equal(Object.keys(want).length, 7);
    for (const [name, p] of Object.entries(want)) assert.deepEqual(shown[name], p, `${name} at t = ${t}`);
    const clock = await page.textContent("#replay-time");
    assert.ok(clock.startsWith(`${t.toFixed(1)} /`), clock);
  }
  // Back to t = 200 and drawn: the screenshot for the docs.
  await page.evaluate(() => { const s = document.getElementById("scrub"); s.value = "200"; s.dispatchEvent(new Event("input")); });
  await page.waitForTimeout(400);
  await shot(page, "replay");
  // Play: time goes on by itself.
  await page.selectOption("#replay-speed", "50");
  await page.click("#play");
  await page.waitForTimeout(1000);
  const t = await page.evaluate(() => window.aviary.replay.t);
  assert.ok(t > 230, `playing at 50×, a second later t = ${t}`);
  await page.click("#play");
  assert.deepEqual(page.foreign, []);
});
