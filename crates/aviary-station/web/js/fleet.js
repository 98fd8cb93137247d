// The fleet grid: a row per drone, its state, battery, altitude, speed, link and running
// activity, with the per-drone actions. Rows are made once and their cells rewritten at
// most a few times a second.

import { batteryColor } from "./map.js";

export class FleetGrid {
  constructor(table, act) {
    this.body = table.tBodies[0];
    this.rows = new Map();
    this.act = act; // (drone, action) => void; none in a replay, which steers nothing
  }

  clear() {
    this.body.textContent = "";
    this.rows.clear();
  }

  row(d) {
    let r = this.rows.get(d.name);
    if (r) return r;
    const tr = document.createElement("tr");
    tr.dataset.drone = d.name;
    const cells = [];
    for (let i = 0; i < 7; i++) cells.push(tr.insertCell());
    cells[0].textContent = d.name;
    const actions = tr.insertCell();
    for (const [action, label, title] of !this.act ? [] : [
      ["hold", "Hold", "pause all its activities"],
      ["resume", "Resume", "go on after a hold"],
      ["home", "Home", "abort its activities and send it home; the mission goes on"],
      ["land", "Land", "abort its activities and land where it is"],
    ]) {
      const b = document.createElement("button");
      b.textContent = label; b.title = title; b.dataset.action = action;
      b.onclick = () => this.act(d.name, action);
      actions.appendChild(b);
    }
    const battery = document.createElement("span");
    battery.className = "battery";
    const fill = document.createElement("i");
    battery.appendChild(fill);
    cells[2].appendChild(battery);
    const text = document.createElement("span");
    cells[2].appendChild(text);
    this.body.appendChild(tr);
    r = { tr, cells, fill, text };
    this.rows.set(d.name, r);
    return r;
  }

  update(model) {
    // Rows are made for every drone, but with many only those in view are rewritten:
    // a thousand rows a few times a second would take the frames the map needs.
    let drones = [...model.drones.values()];
    for (const d of drones) this.row(d);
    if (drones.length > 60) {
      const box = this.body.closest(".panel") || this.body.parentElement;
      const height = this.body.rows[0]?.offsetHeight || 20;
      const first = Math.max(0, Math.floor((box.scrollTop - 40) / height) - 2);
      const count = Math.ceil(box.clientHeight / height) + 4;
      drones = drones.slice(first, first + count);
    }
    for (const d of drones) {
      const r = this.row(d);
      r.tr.classList.toggle("held", d.held);
      r.tr.classList.toggle("withdrawn", d.withdrawn);
      const state = d.withdrawn ? `${d.state} (out)` : d.held ? `${d.state} (held)` : d.state;
      set(r.cells[1], state);
      const b = d.battery;
      r.fill.style.width = b === null ? "0" : `${Math.max(0, Math.min(1, b)) * 100}%`;
      r.fill.style.background = batteryColor(b);
      set(r.text, b === null ? " –" : ` ${(b * 100).toFixed(0)} %`);
      set(r.cells[3], d.pos ? `${d.pos[2].toFixed(1)} m` : "–");
      set(r.cells[4], `${d.speed.toFixed(1)} m/s`);
      set(r.cells[5], d.link);
      set(r.cells[6], (d.activity || "–") + (d.streaming ? " · streaming" : ""));
    }
  }
}

function set(element, text) {
  if (element.textContent !== text) element.textContent = text;
}
