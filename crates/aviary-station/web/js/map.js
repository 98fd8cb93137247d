// The map: the world in its local frame (metres east and north of the origin; Leaflet's
// CRS.Simple, one unit a metre), with the geofence, areas, lines, no-fly zones, places, homes, targets and
// finds as Leaflet layers, and the drones on a canvas of their own over it, redrawn once
// a frame at most: a thousand moving markers as DOM elements would not keep 30 frames a
// second. A world with `tiles` and an `origin` is drawn over its base map instead
// (Leaflet's Web Mercator), each local point placed by the station's figures of the one
// projection (`base`: degrees per metre about the origin).

/* global L */

export function batteryColor(b) {
  if (b === null || b === undefined) return "#8792a6";
  if (b < 0.15) return "#c2352b";
  if (b < 0.35) return "#e08a00";
  return "#1f8a4c";
}

const sameBase = (a, b) => JSON.stringify(a || null) === JSON.stringify(b || null);

export class StationMap {
  constructor(element) {
    this.element = element;
    this.canvas = document.createElement("canvas");
    this.canvas.className = "drone-canvas";
    Object.assign(this.canvas.style, { position: "absolute", inset: "0", zIndex: 450, pointerEvents: "none" });
    this.model = null;
    this.dirty = true;
    this.frames = 0;
    this.build(null);
    const loop = () => {
      if (this.dirty) this.draw();
      this.frames++;
      requestAnimationFrame(loop);
    };
    requestAnimationFrame(loop);
  }

  /// A Leaflet map in the local frame (`base` null) or over a world's tiles; a map's
  /// frame cannot change, so another frame is another map.
  build(base) {
    if (this.map) this.map.remove();
    this.base = base;
    const options = { zoomSnap: 0.25, preferCanvas: true, attributionControl: Boolean(base) };
    if (base) Object.assign(options, { minZoom: 3, maxZoom: 21 });
    else Object.assign(options, { crs: L.CRS.Simple, minZoom: -8, maxZoom: 6 });
    this.map = L.map(this.element, options);
    if (base) {
      this.tiles = L.tileLayer(base.url, { attribution: base.attribution || "", maxNativeZoom: 19, maxZoom: 21 });
      this.tiles.addTo(this.map);
      if (this.map.attributionControl) this.map.attributionControl.setPrefix(false);
      this.map.setView(this.toLatLng([0, 0]), 16);
    } else {
      this.tiles = null;
      this.map.setView([0, 0], 0);
    }
    this.world = L.layerGroup().addTo(this.map);
    this.findLayer = L.layerGroup().addTo(this.map);
    this.findCount = 0;
    this.element.appendChild(this.canvas);
    this.map.on("move zoom resize", () => { this.dirty = true; });
    this.dirty = true;
  }

  /// A local point `[x, y]` (metres east, north) where the map draws it.
  toLatLng(p) {
    const b = this.base;
    return b ? L.latLng(b.lat + p[1] * b.lat_per_m, b.lon + p[0] * b.lon_per_m) : L.latLng(p[1], p[0]);
  }

  /// Draws the world: everything but the drones and what they find.
  setWorld(world) {
    const base = (world && world.base) || null;
    if (!sameBase(base, this.base)) this.build(base);
    this.world.clearLayers();
    if (!world) return;
    const at = (p) => this.toLatLng(p);
    const bounds = L.latLngBounds([]);
    const site = world.site || {};
    if (site.geofence) {
      const fence = L.polygon(site.geofence.map(at), { color: "#c2352b", weight: 2, dashArray: "6 4", fill: false });
      fence.bindTooltip("geofence").addTo(this.world);
      bounds.extend(fence.getBounds());
    }
    for (const a of world.areas || []) {
      const p = L.polygon(a.polygon.map(at), { color: "#1c64d1", weight: 1, fillOpacity: 0.08 });
      p.bindTooltip(a.name, { permanent: true, direction: "center", className: "place-label" }).addTo(this.world);
      bounds.extend(p.getBounds());
    }
    // Lines (a pipeline, a road, a river): a path in teal, named along it.
    for (const l of world.lines || []) {
      const p = L.polyline(l.points.map(at), { color: "#0f8a7e", weight: 3, opacity: 0.8 });
      p.bindTooltip(`line: ${l.name}`, { permanent: true, direction: "center", className: "place-label" }).addTo(this.world);
      bounds.extend(p.getBounds());
    }
    // No-fly zones: red, filled half-transparent, named (with their height, if any).
    for (const z of world.no_fly || []) {
      const p = L.polygon(z.polygon.map(at), { color: "#c2352b", weight: 2, fillColor: "#c2352b", fillOpacity: 0.3 });
      const label = z.up_to == null ? `no-fly: ${z.name}` : `no-fly: ${z.name} (up to ${z.up_to} m)`;
      p.bindTooltip(label, { permanent: true, direction: "center", className: "place-label" }).addTo(this.world);
      bounds.extend(p.getBounds());
    }
    for (const p of world.places || []) {
      const m = L.circleMarker(at(p.at), { radius: 4, color: "#3b4456", weight: 1, fillOpacity: 0.8 });
      m.bindTooltip(p.name, { permanent: true, direction: "right", className: "place-label" }).addTo(this.world);
      bounds.extend(m.getLatLng());
    }
    for (const d of world.drones || []) {
      const [x, y] = d.home;
      const h = L.rectangle([at([x - 1.5, y - 1.5]), at([x + 1.5, y + 1.5])], { color: "#6b7385", weight: 1, fillOpacity: 0.3 });
      h.bindTooltip(`home of ${d.name}`).addTo(this.world);
      bounds.extend(at(d.home));
    }
    for (const t of world.targets || []) {
      const m = L.circleMarker(at(t.at), { radius: 3, color: "#7b4bc4", weight: 1, fillOpacity: 0.6 });
      m.bindTooltip(`target: ${t.kind}`).addTo(this.world);
    }
    if (bounds.isValid()) this.map.fitBounds(bounds.pad(0.15));
    this.dirty = true;
  }

  /// Follows `model`'s drones from now on.
  follow(model) {
    this.model = model;
    this.findCount = 0;
    this.spotCount = 0;
    this.findLayer.clearLayers();
    this.dirty = true;
  }

  changed() {
    this.dirty = true;
  }

  draw() {
    this.dirty = false;
    const size = this.map.getSize();
    const ratio = window.devicePixelRatio || 1;
    if (this.canvas.width !== size.x * ratio || this.canvas.height !== size.y * ratio) {
      this.canvas.width = size.x * ratio; this.canvas.height = size.y * ratio;
      this.canvas.style.width = size.x + "px"; this.canvas.style.height = size.y + "px";
    }
    const ctx = this.canvas.getContext("2d");
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    ctx.clearRect(0, 0, size.x, size.y);
    const model = this.model;
    if (!model) return;
    while (this.findCount < model.finds.length) {
      const f = model.finds[this.findCount++];
      L.circleMarker(this.toLatLng(f.at), { radius: 7, color: "#c2352b", weight: 2, fill: false })
        .bindTooltip(`${f.kind} found by ${f.actor} at t = ${f.t.toFixed(1)} s`).addTo(this.findLayer);
    }
    // Where a signal said (a find, the operator's position) and where a payload was
    // dropped: a square, violet for a signal, green for a drop.
    while (this.spotCount < model.spots.length) {
      const s = model.spots[this.spotCount++];
      const color = s.kind === "drop" ? "#2e7d32" : "#7b4bc4";
      const [x, y] = s.at;
      L.rectangle([this.toLatLng([x - 3, y - 3]), this.toLatLng([x + 3, y + 3])], { color, weight: 2, fillOpacity: 0.25, className: `spot-${s.kind}` })
        .bindTooltip(`${s.text} at t = ${s.t.toFixed(1)} s`).addTo(this.findLayer);
    }
    const point = (p) => this.map.latLngToContainerPoint(this.toLatLng(p));
    const many = model.drones.size > 200;
    // Trails first, under every drone.
    ctx.lineWidth = 1.5;
    for (const d of model.drones.values()) {
      if (d.trail.length < 2) continue;
      ctx.strokeStyle = "rgba(28,100,209,0.35)";
      ctx.beginPath();
      const step = many ? Math.ceil(d.trail.length / 8) : 1;
      let first = true;
      for (let i = 0; i < d.trail.length; i += step) {
        const q = point(d.trail[i]);
        if (first) { ctx.moveTo(q.x, q.y); first = false; } else ctx.lineTo(q.x, q.y);
      }
      const last = point(d.trail[d.trail.length - 1]);
      ctx.lineTo(last.x, last.y);
      ctx.stroke();
    }
    ctx.font = "11px system-ui, sans-serif";
    // Names of drones close together on the screen are written once, as `first +N`: the
    // labels never overlap one another.
    const labels = [];
    for (const d of model.drones.values()) {
      if (!d.pos) continue;
      const q = point(d.pos);
      if (q.x < -20 || q.y < -20 || q.x > size.x + 20 || q.y > size.y + 20) continue;
      if (!many) {
        const near = labels.find((l) => Math.abs(l.x - q.x) < 60 && Math.abs(l.y - q.y) < 12);
        if (near) near.more++;
        else labels.push({ x: q.x, y: q.y, name: d.name, more: 0 });
      }
      if (d.streaming) {
        ctx.beginPath();
        ctx.arc(q.x, q.y, 11, 0, 2 * Math.PI);
        ctx.strokeStyle = "#c2352b";
        ctx.lineWidth = 1.5;
        ctx.setLineDash([3, 2]);
        ctx.stroke();
        ctx.setLineDash([]);
      }
      ctx.save();
      ctx.translate(q.x, q.y);
      ctx.rotate(d.heading);
      ctx.beginPath();
      ctx.moveTo(0, -8); ctx.lineTo(5.5, 6); ctx.lineTo(0, 3); ctx.lineTo(-5.5, 6); ctx.closePath();
      ctx.fillStyle = batteryColor(d.battery);
      ctx.globalAlpha = d.state === "Landed" || d.state === "Lost" ? 0.55 : 1;
      ctx.fill();
      ctx.lineWidth = d.held ? 3 : 1;
      ctx.strokeStyle = d.held ? "#7b4bc4" : d.link === "lost" ? "#c2352b" : "#16202e";
      ctx.stroke();
      ctx.restore();
    }
    ctx.fillStyle = "#16202e";
    for (const l of labels) ctx.fillText(l.more ? `${l.name} +${l.more}` : l.name, l.x + 9, l.y + 4);
    this.labels = labels.map((l) => (l.more ? `${l.name} +${l.more}` : l.name));
  }
}
