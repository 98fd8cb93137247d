// Raising a signal from the page: the Raise control offers the signals the mission
// declares (OPERATOR SIGNAL), and a name it does not declare is refused with them.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { browser, choose, examples, open, start } from "./harness.mjs";

let station, chromium;

before(async () => {
  station = await start(["gcs", examples(), "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
});

test("Raise offers the declared signals, refuses a slip with them, and raises a declared one", async () => {
  const page = await open(chromium, station);
  await choose(page, "drills/inspection.mission");
  await page.fill("#speed", "5");
  await page.click("#fly");
  await page.waitForFunction(() => document.querySelectorAll("#signals option").length > 0, null, { timeout: 60000 });
  const offered = await page.evaluate(() => [...document.querySelectorAll("#signals option")].map((o) => o.value));
  assert.deepEqual(offered, ["Hold_Scout", "Free_Scout"], "in the order the mission declares them");
  await page.fill("#signal-name", "Hold_Scot");
  await page.click("#signal-form button");
  await page.waitForFunction(() => window.aviary.model.alarms.some((a) => a.kind === "refused"));
  const text = await page.evaluate(() => window.aviary.model.alarms.find((a) => a.kind === "refused").text);
  assert.match(text, /does not declare Hold_Scot as an operator signal: did you mean `Hold_Scout`\? It declares Hold_Scout, Free_Scout/);
  await page.fill("#signal-name", "Hold_Scout");
  await page.click("#signal-form button");
  await page.waitForFunction(() => [...document.querySelectorAll("#log li")].some((li) => li.textContent.includes("signal Hold_Scout")));
});
