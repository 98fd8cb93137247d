// The station's scale benchmark (docs/BENCHMARKS.md, "The ground station at scale"):
// 1,000 simulated drones sending 10 telemetry samples a second each, flown in real time
// from `aviary gcs`, watched by the page in headless Chromium; and beside it a client
// whose socket never reads. Measures the page's frames per second, and how fast mission
// time goes against the wall clock (1.0: the mission is not slowed). Exits 1 under
// 30 frames a second or when the mission falls behind.
//
//   node scale.bench.mjs [DRONES] [SECONDS]        defaults: 1000 10

import { execFileSync } from "node:child_process";
import { mkdtempSync, writeFileSync, readFileSync } from "node:fs";
import net from "node:net";
import os from "node:os";
import { join } from "node:path";
import { AVIARY, browser, open, start } from "./harness.mjs";

const DRONES = Number(process.argv[2] || 1000);
const SECONDS = Number(process.argv[3] || 10);
const dir = mkdtempSync(join(os.tmpdir(), "aviary-scale-"));
writeFileSync(join(dir, "scale.mission"), execFileSync(AVIARY, ["bench", "swarm", "--drones", String(DRONES), "--emit"]));
writeFileSync(join(dir, "scale.world.toml"), execFileSync(AVIARY, ["bench", "swarm", "--drones", String(DRONES), "--emit-world"]));

const station = await start(["gcs", dir, "--listen", "0"]);
const chromium = await browser();
let failed = false;
try {
  const fly = await fetch(station.url + "/api/station/fly", {
    method: "POST",
    headers: { "Content-Type": "application/json", Authorization: "Bearer " + station.token },
    body: JSON.stringify({
      mission: { path: "scale.mission", text: readFileSync(join(dir, "scale.mission"), "utf8") },
      world: { path: "scale.world.toml", text: readFileSync(join(dir, "scale.world.toml"), "utf8") },
      speed: 1,
      telemetry_hz: 10,
    }),
  });
  if (!fly.ok) throw new Error(`fly: ${fly.status} ${await fly.text()}`);

  // A client that opens the batched stream and never reads a byte of it.
  const url = new URL(station.url);
  const stalled = net.connect(Number(url.port), url.hostname, () => {
    stalled.write(`GET /api/events?every=100 HTTP/1.1\r\nHost: ${url.host}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n` +
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n");
    stalled.pause();
  });

  const page = await open(chromium, station);
  await page.waitForFunction((n) => window.aviary.model.drones.size >= n &&
    [...window.aviary.model.drones.values()].filter((d) => d.trail.length > 3).length >= n * 0.9, DRONES, { timeout: 120000 });
  const state = async () => (await (await fetch(station.url + "/api/state")).json()).t;
  const before = { wall: Date.now(), t: await state(), frames: await page.evaluate(() => window.aviary.map.frames) };
  const samples = await page.evaluate(async (seconds) => {
    // Frames the page draws, second by second.
    const per = [];
    for (let s = 0; s < seconds; s++) {
      const start = window.aviary.map.frames;
      await new Promise((r) => setTimeout(r, 1000));
      per.push(window.aviary.map.frames - start);
    }
    return per;
  }, SECONDS);
  const after = { wall: Date.now(), t: await state(), frames: await page.evaluate(() => window.aviary.map.frames) };
  const fps = (after.frames - before.frames) / ((after.wall - before.wall) / 1000);
  const pace = (after.t - before.t) / ((after.wall - before.wall) / 1000);
  const shown = await page.evaluate(() => ({ drones: window.aviary.model.drones.size, t: window.aviary.model.t }));
  const cpu = os.cpus()[0].model;
  console.log(`station scale: ${DRONES} drones x 10 Hz telemetry, ${SECONDS} s; ${os.cpus().length} x ${cpu}`);
  console.log(`page: ${fps.toFixed(1)} frames/s (per second: ${samples.join(" ")}); ${shown.drones} drones shown`);
  console.log(`mission: ${pace.toFixed(3)} s of mission time per wall second, with a client that never reads`);
  if (fps < 30) { console.error(`FAIL: ${fps.toFixed(1)} frames/s, under 30`); failed = true; }
  if (pace < 0.9) { console.error(`FAIL: the mission went at ${pace.toFixed(3)}x real time`); failed = true; }
  stalled.destroy();
  await fetch(station.url + "/api/abort", { method: "POST", headers: { "Content-Type": "application/json", Authorization: "Bearer " + station.token }, body: "{}" });
} finally {
  await chromium.close();
  station.process.kill("SIGTERM");
}
process.exit(failed ? 1 : 0);
