// A position raised from the page: the Raise form takes it as one value, `GEO(lat, lon)`
// or `x, y`; the drone flies where the server placed it, and a position beyond the
// world's geofence is refused with the server's reason, shown to the operator.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { browser, choose, examples, open, position, shot, start } from "./harness.mjs";

const MISSION = `MISSION Go_There:
    OPERATOR SIGNAL Go
    PARALLEL:
        a Hover WITH 300s
        ON EVERY Go WITH where:
            b FlyTo WITH where
`;

/// A fence of ±300 m about an origin at 47.45° N 13.10° E.
const WORLD = `[site]
origin = { lat = 47.45, lon = 13.10, alt = 500 }
geofence = [[-300, -300], [300, -300], [300, 300], [-300, 300]]
max_altitude = 120

[drones.a]
home = [0, 0]
[drones.b]
home = [10, 0]
`;

let station, chromium;

before(async () => {
  const dir = examples();
  writeFileSync(join(dir, "drills/go_there.mission"), MISSION);
  writeFileSync(join(dir, "drills/go_there.world.toml"), WORLD);
  station = await start(["gcs", dir, "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
});

/// Waits until drone `name` is within 2 m of `[x, y]` on the page's map.
async function reaches(page, name, [x, y]) {
  await page.waitForFunction(([n, x, y]) => {
    const p = window.aviary.model.drones.get(n)?.pos;
    return p && Math.hypot(p[0] - x, p[1] - y) < 2;
  }, [name, x, y], { timeout: 60000 });
}

test("Raise takes a position as GEO(lat, lon) or x, y, and shows why one beyond the fence is refused", async () => {
  const page = await open(chromium, station);
  await choose(page, "drills/go_there.mission");
  await page.fill("#speed", "10");
  await page.click("#fly");
  await page.waitForFunction(() => document.querySelectorAll("#signals option").length > 0, null, { timeout: 60000 });
  await page.fill("#signal-name", "Go");
  await page.dispatchEvent("#signal-name", "input");
  assert.equal(await page.getAttribute("#signal-args", "placeholder"), "GEO(lat, lon) or x, y");

  // 0.0005° north and east of the origin: 55.6 m north, 37.6 m east.
  await page.fill("#signal-args", "GEO(47.4505, 13.1005)");
  await page.click("#signal-form button");
  await reaches(page, "b", [37.6, 55.6]);

  await page.fill("#signal-args", "-50, 40");
  await page.click("#signal-form button");
  await reaches(page, "b", [-50, 40]);

  await page.fill("#signal-args", "GEO(47.46, 13.10)");
  await page.click("#signal-form button");
  await page.waitForFunction(() => window.aviary.model.alarms.some((a) => a.kind === "refused"));
  const text = await page.evaluate(() => window.aviary.model.alarms.find((a) => a.kind === "refused").text);
  assert.equal(text, "signal Go: value 1 of Go: GEO(47.46, 13.1), at (0, 1111.9), is outside the geofence, 811.9 m beyond its nearest side: choose a position inside it");
  await page.waitForFunction(() => document.getElementById("alarms").textContent.includes("811.9 m beyond its nearest side"));
  await shot(page, "raise-position");

  // The refusal changed nothing: the mission runs on, and b stays where it was sent.
  const state = await page.evaluate(() => fetch("/api/state").then((r) => r.json()));
  assert.equal(state.status, "running");
  const b = await position(page, "b");
  assert.ok(Math.hypot(b[0] + 50, b[1] - 40) < 2, `b at ${b}`);
  assert.deepEqual(page.foreign, []);
});
