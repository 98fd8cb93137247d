// A world with a base map: `[site] tiles` names a tile server (here one of the test's own
// on loopback, standing in for a city's or a brigade's offline server), and the station's
// map draws the world and the drones over its tiles, placed by the world's origin. The
// page may load images from that server and from nowhere else.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { createServer } from "node:http";
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { browser, examples, open, shot, start } from "./harness.mjs";

let station, chromium, dir, tiles;
const asked = [];

/// One tile: a light grid with its coordinates, so that a screenshot shows the base map.
function tile(z, x, y) {
  return `<svg xmlns="http://www.w3.org/2000/svg" width="256" height="256">
<rect width="256" height="256" fill="#eef3e6" stroke="#b9c4a7"/>
<path d="M0 128H256M128 0V256" stroke="#d5dcc8"/>
<text x="8" y="20" font-family="sans-serif" font-size="12" fill="#7d8a68">tile ${z}/${x}/${y}</text></svg>`;
}

before(async () => {
  tiles = createServer((req, res) => {
    const m = req.url.match(/^\/tiles\/(\d+)\/(\d+)\/(\d+)\.svg$/);
    asked.push(req.url);
    if (!m) { res.writeHead(404).end(); return; }
    res.writeHead(200, { "Content-Type": "image/svg+xml" }).end(tile(m[1], m[2], m[3]));
  });
  await new Promise((r) => tiles.listen(0, "127.0.0.1", r));
  dir = examples();
  const world = join(dir, "search_and_rescue.world.toml");
  const url = `http://127.0.0.1:${tiles.address().port}/tiles/{z}/{x}/{y}.svg`;
  writeFileSync(world, readFileSync(world, "utf8").replace(
    "max_altitude = 120.0\n",
    `max_altitude = 120.0\ntiles = "${url}"\ntiles_attribution = "test tiles"\n`,
  ));
  station = await start(["gcs", dir, "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
  tiles?.close();
});

test("a world's tile URL puts the map over a real base map, placed by the origin", async () => {
  const page = await open(chromium, station);
  await page.waitForSelector("#check-summary.good");
  // The tiles load (from the world's server only), with their attribution shown.
  await page.waitForFunction(() => document.querySelectorAll("#map img.leaflet-tile-loaded").length >= 4);
  assert.ok(asked.some((u) => /^\/tiles\/1\d\/\d+\/\d+\.svg$/.test(u)), `tiles asked at a street-level zoom: ${asked.slice(0, 5)}`);
  assert.match(await page.textContent("#map .leaflet-control-attribution"), /test tiles/);
  const foreign = page.foreign.filter((u) => !u.startsWith(`http://127.0.0.1:${tiles.address().port}/tiles/`));
  assert.deepEqual(foreign, [], "nothing but the world's tiles came from elsewhere");
  // The local frame sits on the Earth where the origin says: (0, 0) at the origin,
  // 1 km north about 0.009° of latitude further.
  const placed = await page.evaluate(() => {
    const m = window.aviary.map;
    const o = m.toLatLng([0, 0]), n = m.toLatLng([0, 1000]), e = m.toLatLng([1000, 0]);
    return { o: [o.lat, o.lng], north: n.lat - o.lat, east: e.lng - o.lng, crs: m.map.options.crs.code };
  });
  assert.equal(placed.crs, "EPSG:3857");
  assert.ok(Math.abs(placed.o[0] - 46.6167) < 1e-9 && Math.abs(placed.o[1] - 14.265) < 1e-9, `${placed.o}`);
  assert.ok(Math.abs(placed.north - 1000 / 6371000 * 180 / Math.PI) < 1e-9, `${placed.north}`);
  assert.ok(Math.abs(placed.east - 1000 / (6371000 * Math.cos(46.6167 * Math.PI / 180)) * 180 / Math.PI) < 1e-9, `${placed.east}`);
  // The drones fly over it, and are drawn where their positions are.
  await page.fill("#speed", "40");
  await page.click("#fly");
  await page.waitForFunction(() => window.aviary.model.t > 60);
  const drawn = await page.evaluate(() => {
    const m = window.aviary.map;
    const d = [...window.aviary.model.drones.values()].find((x) => x.pos);
    const p = m.map.latLngToContainerPoint(m.toLatLng(d.pos));
    const size = m.map.getSize();
    return { inside: p.x >= 0 && p.y >= 0 && p.x <= size.x && p.y <= size.y };
  });
  assert.ok(drawn.inside, "a flying drone is drawn on the visible map");
  await page.waitForTimeout(300);
  await shot(page, "basemap");
  // A page of the station may not load images from any other server: the policy names
  // this one alone.
  const policy = await page.evaluate(async () => (await fetch("/")).headers.get("content-security-policy"));
  assert.match(policy, new RegExp(`img-src 'self' data: http://127\\.0\\.0\\.1:${tiles.address().port};`));
});

test("a world without an origin cannot have a base map: the check says why", async () => {
  const page = await open(chromium, station);
  await page.waitForSelector("#check-summary.good");
  const world = await page.evaluate(() => window.aviary.editor.files.world.path);
  assert.equal(world, "search_and_rescue.world.toml");
  const checked = await page.evaluate(async () => {
    const text = window.aviary.editor.files.world.text.replace(/^origin = .*\n/m, "");
    const r = await fetch("/api/station/check", {
      method: "POST",
      headers: { "Content-Type": "application/json" },
      body: JSON.stringify({ mission: window.aviary.editor.files.mission, world: { path: "search_and_rescue.world.toml", text } }),
    });
    return r.json();
  });
  const messages = JSON.stringify(checked);
  assert.match(messages, /needs the site's `origin`/);
});
