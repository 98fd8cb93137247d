// Before MAVLink drones fly from the page, the station plans again with each vehicle's own
// figures, as `aviary run` does, and the operator sees its warnings as alarms: here the
// scout's vehicle reports 12 % of charge where the world says 100 %.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { browser, mavlinkPatrol, open, shot, start } from "./harness.mjs";

let station, chromium, vehicles, dir;

before(async () => {
  // The vehicles' own world: the scout's battery is nearly empty.
  ({ dir, vehicles } = await mavlinkPatrol("aviary-gcs-plan-", (w) => w.replace("[drones.scout]\n", "[drones.scout]\nbattery = 12\n")));
  station = await start(["gcs", dir, "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
  vehicles?.kill("SIGTERM");
});

test("the plan with the vehicles' figures warns the operator, as aviary run does", async () => {
  const page = await open(chromium, station);
  await page.waitForSelector("#mission-file option", { state: "attached" });
  await page.selectOption("#mission-file", "patrol.mission");
  await page.waitForSelector("#check-summary.good");
  // With the world's figures the check is clean: the warning needs the vehicle's charge.
  assert.ok(!/warning/.test(await page.textContent("#check-summary")), await page.textContent("#check-summary"));
  await page.fill("#speed", "");
  await page.click("#fly");
  await page.waitForFunction(() => window.aviary.model.alarms.some((a) => a.kind === "plan"), null, { timeout: 60000 });
  const alarms = await page.evaluate(() => window.aviary.model.alarms.filter((a) => a.kind === "plan").map((a) => a.text));
  assert.ok(alarms.some((a) => /W204/.test(a) && /scout's battery/.test(a)), `the plan's warnings: ${alarms}`);
  const shown = await page.evaluate(() => [...document.querySelectorAll('#alarms .alarm[data-kind="plan"] span')].map((s) => s.textContent));
  assert.ok(shown.some((s) => s.includes("scout")), `shown: ${shown}`);
  await shot(page, "vehicle-plan");
  // The CLI says the same of the same drones.
  const state = await page.evaluate(async () => (await fetch("/api/station")).json());
  assert.ok(Array.isArray(state.run.vehicle_plan) && state.run.vehicle_plan.length >= 1);
  await page.waitForFunction(() => !["running", "paused"].includes(document.getElementById("status").textContent), null, { timeout: 240000 });
});
