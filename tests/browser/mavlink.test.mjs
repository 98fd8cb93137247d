// Flying MAVLink drones from the page, as `aviary run` flies such a world: the fleet
// served by the real `aviary vehicles` on loopback (ArduCopter-like vehicles, here at 10
// times real time so that the test is short), each drone its own MAVLink system.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { spawn } from "node:child_process";
import { mkdtempSync, readFileSync, writeFileSync, cpSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { AVIARY, ROOT, browser, open, shot, start } from "./harness.mjs";

let station, chromium, vehicles, dir;

const ORIGIN = "origin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }\n";

/// Starts `aviary vehicles` on a free port; resolves to the port.
function serveVehicles(world) {
  return new Promise((resolve, reject) => {
    vehicles = spawn(AVIARY, ["vehicles", "--world", world, "--listen", "tcp:127.0.0.1:0", "--speed", "10"],
      { stdio: ["ignore", "pipe", "ignore"] });
    let out = "";
    vehicles.stdout.on("data", (c) => {
      out += c.toString();
      const m = out.match(/127\.0\.0\.1:(\d+)/);
      if (m) resolve(Number(m[1]));
    });
    vehicles.on("exit", (code) => reject(new Error(`aviary vehicles exited ${code}: ${out}`)));
  });
}

before(async () => {
  dir = mkdtempSync(join(tmpdir(), "aviary-gcs-mavlink-"));
  cpSync(join(ROOT, "tests/browser/fixtures"), dir, { recursive: true });
  const plain = readFileSync(join(dir, "patrol.world.toml"), "utf8").replace("[site]\n", `[site]\n${ORIGIN}`);
  writeFileSync(join(dir, "vehicles.world.toml.txt"), plain);
  const port = await serveVehicles(join(dir, "vehicles.world.toml.txt"));
  let bound = plain;
  for (const d of ["scout", "carrier", "spare"])
    bound = bound.replace(`[drones.${d}]\n`, `[drones.${d}]\nmavlink = "tcp:127.0.0.1:${port}"\n`);
  writeFileSync(join(dir, "patrol.world.toml"), bound);
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
