"""The page's script (vanilla JavaScript, no library): it reads the JSON
document :mod:`ignjax.view.page` embeds and builds the index and the
episode pages in the DOM. Routing is the URL fragment (``#`` the index,
``#ep=<row>&a=<agent>[&b=<agent>]`` an episode, agent B side by side), so
the browser's back button and links work on a file opened from disk.

The index's rows are built once and then only hidden, shown and re-ordered
(filters, sorting), which keeps 500 episodes x 5 agents responsive. Each
episode panel draws its SVG map once; the step slider moves the agent
marker (``circle.agent-marker``: ``cx``/``cy`` in metres, world frame
inside a y-flipped group), the drawn path, the step's waypoint and blocked
headings, and fills the step's details. Step ``t`` (0-based planner step,
as in the outcome tables) is the decision taken at pose ``t``; the
slider's last position is the end of the episode.
"""

SCRIPT = r"""
"use strict";
(function () {
const D = JSON.parse(document.getElementById("ignjax-data").textContent);
const E = D.episodes, A = D.agents, NS = "http://www.w3.org/2000/svg";
const QCOL = ["#7d3c98", "#e67e22", "#c0392b", "#27ae60"];
const PATH_COL = ["#1f3b73", "#b03a2e"];

function h(tag, attrs, ...kids) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === "text") e.textContent = v; else if (k === "cls") e.className = v;
    else if (k.startsWith("on")) e.addEventListener(k.slice(2), v); else e.setAttribute(k, v);
  }
  for (const c of kids) if (c !== null && c !== undefined) e.append(c);
  return e;
}
function s(tag, attrs, parent) {
  const e = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}
function pts(flat) { const o = []; for (let i = 0; i < flat.length; i += 2) o.push(flat[i] + "," + flat[i + 1]); return o.join(" "); }
const f2 = x => Number(x).toFixed(2), f3 = x => Number(x).toFixed(3);
function dots(succ) { const sp = h("span", {title: D.thresholds.map((t, j) => t + " m: " + (succ[j] ? "success" : "failure")).join(", ")});
  succ.forEach(v => sp.append(h("span", {cls: "dot " + (v ? "ok" : "bad")}))); return sp; }
function qtxt(q) { return q.join("\u00b7"); }
function endWord(stop) { return stop === "step_budget" ? "budget" : stop; }
function route(ep, a, b) { location.hash = "ep=" + ep + "&a=" + encodeURIComponent(a) + (b ? "&b=" + encodeURIComponent(b) : ""); }

// ---------------------------------------------------------------- header
document.getElementById("title").textContent = D.title;
document.getElementById("summary").textContent = D.benchmark + ": " + E.length + " episodes x " + A.length +
  " agents (" + A.join(", ") + "); " + D.rule + "; costs " + D.costs.join(", ") + (D.upfront ?
  "; the target's description was given at reset (charged as Type 1 + Type 2)" : "");
const notices = document.getElementById("notices");
if (E.length < D.n_run_episodes) notices.append(h("div", {cls: "notice", text: "This page holds the first " +
  E.length + " of the run's " + D.n_run_episodes + " episodes (--episodes)."}));
if (D.images_left_out > 0) notices.append(h("div", {cls: "notice", text: D.images_left_out + " agent episodes " +
  "have images in the run folder that this page leaves out; python -m ignjax.view RUN_DIR --episodes N embeds " +
  "them for the first N episodes."}));

// ---------------------------------------------------------------- index
const FIELDS = [
  ["succ", "S@" + D.thresholds.join("/"), r => r.succ.reduce((a, b) => a + b, 0) * 1000 - r.fd],
  ["fd", "d (m)", r => r.fd], ["disc", "disc", r => r.disc], ["q", "Q1\u00b7Q2\u00b7Q3\u00b7Q4", r => r.q.reduce((a, b) => a + b, 0)],
  ["stop", "end", r => r.stop]];
const EPF = [["row", "#", i => i], ["id", "episode", i => E[i].id], ["scene", "scene", i => E[i].scene],
  ["diff", "difficulty", i => ["easy", "medium", "hard"].indexOf(E[i].diff)], ["cat", "target", i => E[i].cat]];
const shown = A.map(() => true);
const sortState = {key: null, desc: false};
let order = E.map((_, i) => i);
const tbody = document.querySelector("#index tbody"), thead = document.querySelector("#index thead");
const rows = [];

function sel(id, label, options) {
  const s_ = h("select", {id: id});
  for (const [v, t] of options) s_.append(h("option", {value: v, text: t}));
  s_.addEventListener("change", applyFilters);
  return h("label", {}, label + " ", s_);
}
function buildFilters() {
  const f = document.getElementById("filters");
  const ag = h("span", {}, "agents: ");
  A.forEach((a, k) => {
    const cb = h("input", {type: "checkbox", "data-agent": a});
    cb.checked = true;
    cb.addEventListener("change", () => { shown[k] = cb.checked; showAgentColumns(); applyFilters(); });
    ag.append(h("label", {}, cb, a), " ");
  });
  f.append(ag,
    sel("f-diff", "difficulty", [["", "all"], ["easy", "easy"], ["medium", "medium"], ["hard", "hard"]]),
    sel("f-out", "outcome", [["", "any"], ["ok", "success"], ["bad", "failure"]]),
    sel("f-tau", "at", D.thresholds.map((t, j) => [String(j), t + " m"])),
    sel("f-ask", "asked", [["", "any"], ["none", "no question"]].concat(D.qtypes.map((q, j) => [String(j + 1), "Type " + (j + 1) + " " + q]))));
  const dis = h("input", {type: "checkbox", id: "f-dis"}); dis.addEventListener("change", applyFilters);
  const search = h("input", {type: "search", id: "f-text", placeholder: "episode id contains", size: "22"});
  search.addEventListener("input", applyFilters);
  f.append(h("label", {}, dis, "agents disagree"), search, h("span", {id: "count"}));
  const tau = document.getElementById("f-tau");
  tau.value = String(Math.min(1, D.thresholds.length - 1));
}
function th(key, text, cls) {
  const e = h("th", {text: text, "data-key": key, cls: cls || ""});
  e.addEventListener("click", () => sortBy(key));
  return e;
}
function buildIndex() {
  const r1 = h("tr"), r2 = h("tr");
  EPF.forEach(([k, t]) => { r1.append(h("th", {rowspan: "2", cls: "ep", "data-key": "e:" + k, text: t, onclick: () => sortBy("e:" + k)})); });
  A.forEach((a, k) => {
    r1.append(h("th", {cls: "group", colspan: String(FIELDS.length), "data-agent": String(k), text: a}));
    FIELDS.forEach(([fk, t], j) => r2.append(th("a:" + k + ":" + fk, t, j === 0 ? "first" : "")));
  });
  r2.querySelectorAll("th").forEach(e => { const m = e.dataset.key.split(":"); e.dataset.agent = m[1]; });
  thead.append(r1, r2);
  E.forEach((ep, i) => {
    const tr = h("tr", {"data-episode-id": ep.id, "data-row": String(i)});
    const link = h("a", {href: "#ep=" + i, text: ep.id, title: "open the episode (the first two agents shown side by side)"});
    link.addEventListener("click", ev => { ev.preventDefault(); const k = shown.indexOf(true);
      route(i, A[Math.max(k, 0)], k >= 0 ? firstOtherShown(k) : null); });
    tr.append(h("td", {text: String(i)}), h("td", {}, link),
      h("td", {text: ep.scene}), h("td", {cls: ep.diff, text: ep.diff}), h("td", {text: ep.cat}));
    ep.runs.forEach((r, k) => {
      const go = () => route(i, A[k], null);
      const cells = [h("td", {cls: "run first"}, dots(r.succ)), h("td", {cls: "run", text: f2(r.fd)}),
        h("td", {cls: "run", text: f3(r.disc)}), h("td", {cls: "run", text: qtxt(r.q) + (r.ref ? " (" + r.ref + " refused)" : "")}),
        h("td", {cls: "run", text: endWord(r.stop)})];
      cells.forEach(c => { c.dataset.agent = String(k); c.title = A[k] + ": open the episode"; c.addEventListener("click", go); tr.append(c); });
    });
    rows.push(tr);
  });
  tbody.append(...rows);
}
function firstOtherShown(k) { const j = A.findIndex((a, m) => m !== k && shown[m]); return j >= 0 ? A[j] : null; }
function showAgentColumns() {
  document.querySelectorAll("#index [data-agent]").forEach(e => { e.style.display = shown[+e.dataset.agent] ? "" : "none"; });
}
function sortBy(key) {
  if (sortState.key === key) sortState.desc = !sortState.desc; else { sortState.key = key; sortState.desc = false; }
  let val;
  if (key.startsWith("e:")) { const f = EPF.find(x => x[0] === key.slice(2))[2]; val = i => f(i); }
  else { const [, k, fk] = key.split(":"); const f = FIELDS.find(x => x[0] === fk)[2]; val = i => f(E[i].runs[+k]); }
  const sign = sortState.desc ? -1 : 1;
  order = E.map((_, i) => i).sort((a, b) => { const x = val(a), y = val(b); return (x < y ? -1 : x > y ? 1 : a - b) * sign; });
  thead.querySelectorAll("th").forEach(e => { e.classList.toggle("sorted", e.dataset.key === key); e.classList.toggle("desc", e.dataset.key === key && sortState.desc); });
  tbody.append(...order.map(i => rows[i]));
  applyFilters();
}
function runMatches(r, out, tau, ask) {
  if (out === "ok" && !r.succ[tau]) return false;
  if (out === "bad" && r.succ[tau]) return false;
  if (ask === "none" && r.q.some(v => v > 0)) return false;
  if (ask && ask !== "none" && !(r.q[+ask - 1] > 0)) return false;
  return true;
}
function visibleOrder() { return order.filter(i => rows[i].style.display !== "none"); }
function applyFilters() {
  const diff = document.getElementById("f-diff").value, out = document.getElementById("f-out").value;
  const tau = +document.getElementById("f-tau").value, ask = document.getElementById("f-ask").value;
  const dis = document.getElementById("f-dis").checked, text = document.getElementById("f-text").value.trim();
  let n = 0;
  E.forEach((ep, i) => {
    const runs = ep.runs.filter((r, k) => shown[k]);
    let ok = (!diff || ep.diff === diff) && (!text || ep.id.includes(text)) && runs.length > 0;
    if (ok && (out || ask)) ok = runs.some(r => runMatches(r, out, tau, ask));
    if (ok && dis) ok = runs.some(r => r.succ[tau]) && runs.some(r => !r.succ[tau]);
    rows[i].style.display = ok ? "" : "none";
    n += ok ? 1 : 0;
  });
  document.getElementById("count").textContent = "showing " + n + " of " + E.length + " episodes";
}

// ---------------------------------------------------------------- maps
function drawScene(svg, sc, ep) {
  const [x0, y0, x1, y1] = sc.bounds, p = 0.4;
  svg.setAttribute("viewBox", [x0 - p, -(y1 + p), x1 - x0 + 2 * p, y1 - y0 + 2 * p].join(" "));
  const g = s("g", {transform: "scale(1,-1)"}, svg);
  for (const [, col, poly] of sc.rooms) s("polygon", {points: pts(poly), fill: col, stroke: "none"}, g);
  for (const [ax, ay, bx, by, t] of sc.walls) s("line", {x1: ax, y1: ay, x2: bx, y2: by, stroke: "#2b2b2b", "stroke-width": t}, g);
  for (const [ax, ay, bx, by, kind] of sc.doors)
    s("line", {x1: ax, y1: ay, x2: bx, y2: by, stroke: ["#c0392b", "#2e86c1", "#27ae60"][kind], "stroke-width": 0.06,
               "stroke-dasharray": kind === 1 ? "0.12 0.08" : "none"}, g);
  sc.inst.forEach((it, k) => {
    if (!it) return;
    const poly = s("polygon", {points: pts(it[4]), fill: it[3], stroke: "#000", "stroke-width": 0.01, "fill-opacity": 0.85}, g);
    s("title", {}, poly).textContent = it[0] + ": " + (it[2] ? it[2] + " " : "") + it[1];
  });
  const mark = (k, col, w) => { const it = sc.inst[k]; if (it) s("polygon", {points: pts(it[4]), fill: "none", stroke: col, "stroke-width": w}, g); };
  ep.distr.forEach(k => mark(k, "#e67e22", 0.07));
  if (ep.target >= 0) mark(ep.target, "#f1c40f", 0.1);
  const lab = s("g", {"font-size": 0.32, "text-anchor": "middle", fill: "#333"}, svg);
  for (const [name, , , cx, cy] of sc.rooms) { const t = s("text", {x: cx, y: -cy}, lab); t.textContent = name; }
  if (ep.target >= 0 && sc.inst[ep.target]) { const it = sc.inst[ep.target];
    const t = s("text", {x: it[5], y: -it[6] - 0.25, fill: "#7d6608", "font-weight": "bold"}, lab); t.textContent = "target"; }
  s("circle", {cx: ep.start[0], cy: ep.start[1], r: 0.16, fill: "#fff", stroke: "#000", "stroke-width": 0.05, "class": "start"}, g);
  return g;
}

// ---------------------------------------------------------------- episode panels
function viewOf(rel) { return D.views[((Math.round(rel / (Math.PI / 4)) % 8) + 8) % 8]; }
function attrWords(codes) { return codes.map((c, j) => c >= 0 ? D.attrs[j][c] : "").filter(x => x).join(" "); }
function stepShort(r, t) {
  const k = r.k[t];
  if (k === 0) return "MOVE " + (r.d ? D.views[r.d[t]] + " (col " + r.c[t] + ", row " + r.r[t] + ")" : "");
  if (k === 1) return "ASK Type " + r.qt[t] + " " + D.qtypes[r.qt[t] - 1] + (r.rf && r.rf.includes(t) ? " (refused)" : "");
  return "STOP";
}
function instName(sc, k) { const it = sc.inst[k]; return it ? (it[2] ? it[2] + " " : "") + it[1] + " (" + it[0] + ")" : "instance " + k; }

function Panel(i, k, slot) {
  const ep = E[i], r = ep.runs[k], sc = D.scenes[ep.scene], n = r.n;
  const root = h("div", {cls: "panel", "data-agent": A[k]});
  root.append(h("h3", {}, A[k] + " ", dots(r.succ), " d " + f2(r.fd) + " m, path " + f2(r.pl) + " m, " + n +
    " steps, questions " + qtxt(r.q) + ", WSR discount " + f3(r.disc) + ", ended by " + endWord(r.stop)));
  const svg = s("svg", {"class": "map", preserveAspectRatio: "xMidYMid meet"});
  root.append(svg);
  const g = drawScene(svg, sc, ep), col = PATH_COL[slot];
  const P = t => [r.pose[3 * t], r.pose[3 * t + 1], r.pose[3 * t + 2]];
  const all = [];
  for (let t = 0; t <= n; t++) all.push(P(t)[0], P(t)[1]);
  s("polyline", {points: pts(all), fill: "none", stroke: col, "stroke-opacity": 0.25, "stroke-width": 0.05, "stroke-dasharray": "0.1 0.08"}, g);
  const done = s("polyline", {points: "", fill: "none", stroke: col, "stroke-width": 0.07, "class": "path-done"}, g);
  for (let t = 0; t < n; t++) if (r.k[t] === 1) {
    const c = s("circle", {cx: P(t)[0], cy: P(t)[1], r: 0.13, fill: QCOL[r.qt[t] - 1], stroke: "#000", "stroke-width": 0.02}, g);
    s("title", {}, c).textContent = "step " + t + ": Type " + r.qt[t] + " " + D.qtypes[r.qt[t] - 1];
  }
  const wpLine = s("line", {stroke: "#555", "stroke-width": 0.035, "stroke-dasharray": "0.08 0.06", "class": "waypoint-line"}, g);
  const wp = s("circle", {r: 0.08, fill: "none", stroke: "#555", "stroke-width": 0.04, "class": "waypoint"}, g);
  const blockedG = s("g", {"class": "blocked"}, g);
  const marker = s("circle", {r: 0.2, fill: col, stroke: "#fff", "stroke-width": 0.05, "class": "agent-marker"}, g);
  const heading = s("line", {stroke: "#fff", "stroke-width": 0.06, "class": "agent-heading"}, g);
  root.append(h("div", {cls: "legend"}, ...[["#f1c40f", "target"], ["#e67e22", "distractors"], ["#fff", "start"], [col, "agent"]]
    .map(([c, t]) => h("span", {}, h("span", {cls: "sw", style: "background:" + c}), t)),
    ...D.qtypes.map((q, j) => h("span", {}, h("span", {cls: "sw", style: "border-radius:50%;background:" + QCOL[j]}), "T" + (j + 1) + " " + q))));
  const slider = h("input", {type: "range", min: "0", max: String(n), value: "0", step: "1", cls: "step-slider", "aria-label": "step"});
  const label = h("span", {cls: "step-label"});
  let timer = null;
  const play = h("button", {text: "\u25b6", title: "play"});
  const stopPlay = () => { if (timer) { clearInterval(timer); timer = null; play.textContent = "\u25b6"; } };
  play.addEventListener("click", () => {
    if (timer) return stopPlay();
    if (+slider.value >= n) set(0);
    play.textContent = "\u23f8";
    timer = setInterval(() => { if (+slider.value >= n) stopPlay(); else set(+slider.value + 1); }, 700);
  });
  root.append(h("div", {cls: "controls"}, h("button", {text: "\u25c0", title: "previous step", onclick: () => set(Math.max(0, +slider.value - 1))}),
    slider, h("button", {text: "\u25b6\u2502", title: "next step", onclick: () => set(Math.min(n, +slider.value + 1))}), play, label));
  const detail = h("div", {cls: "detail"});
  const list = h("ol", {cls: "step-list", start: "0"});
  for (let t = 0; t < n; t++) {
    const li = h("li", {"data-step": String(t), cls: ["move", "ask", "stop"][r.k[t]] || "", text: stepShort(r, t)});
    li.addEventListener("click", () => set(t));
    list.append(li);
  }
  root.append(detail, list);
  slider.addEventListener("input", () => set(+slider.value));

  function set(v) {
    slider.value = String(v);
    const [x, y, yaw] = P(v);
    marker.setAttribute("cx", x); marker.setAttribute("cy", y);
    heading.setAttribute("x1", x); heading.setAttribute("y1", y);
    heading.setAttribute("x2", x + 0.3 * Math.cos(yaw)); heading.setAttribute("y2", y + 0.3 * Math.sin(yaw));
    done.setAttribute("points", pts(all.slice(0, 2 * v + 2)));
    blockedG.replaceChildren();
    const moving = v < n && r.k[v] === 0;
    for (const e of [wp, wpLine]) e.style.display = moving && r.wp ? "" : "none";
    if (moving && r.wp) {
      const wx = r.wp[2 * v], wy = r.wp[2 * v + 1];
      wp.setAttribute("cx", wx); wp.setAttribute("cy", wy);
      wpLine.setAttribute("x1", x); wpLine.setAttribute("y1", y); wpLine.setAttribute("x2", wx); wpLine.setAttribute("y2", wy);
    }
    if (moving && r.bl && r.bl[v]) for (let b = 0; b < 8; b++) if (r.bl[v] & (1 << b)) {
      const a = yaw + b * Math.PI / 4;
      s("line", {x1: x + 0.25 * Math.cos(a), y1: y + 0.25 * Math.sin(a), x2: x + 0.6 * Math.cos(a), y2: y + 0.6 * Math.sin(a),
                 stroke: "#e74c3c", "stroke-width": 0.06, "class": "blocked-heading"}, blockedG);
    }
    list.querySelectorAll("li").forEach(li => li.classList.toggle("current", +li.dataset.step === v));
    label.textContent = v < n ? "step " + v + " of " + n : "end (" + n + " steps)";
    fillDetail(v);
  }

  function fillDetail(t) {
    detail.replaceChildren();
    if (t >= n) {
      detail.append(h("p", {cls: "decision", text: "Episode ended by " + (r.stop === "stop" ? "STOP" : "the step budget") +
        " after " + n + " steps."}), h("p", {text: "Final geodesic distance " + f2(r.fd) + " m (closest " + f2(r.md) +
        " m), path " + f2(r.pl) + " m; success at " + D.thresholds.map((th_, j) => th_ + " m " + (r.succ[j] ? "yes" : "no")).join(", ") +
        "; questions " + qtxt(r.q) + (r.ref ? " (" + r.ref + " refused)" : "") + "; WSR discount " + f3(r.disc) + "."}));
      return;
    }
    const k_ = r.k[t], [, , yaw] = P(t);
    let dec = stepShort(r, t);
    if (k_ === 0 && r.wp) dec += " \u2192 waypoint (" + f2(r.wp[2 * t]) + ", " + f2(r.wp[2 * t + 1]) + ")";
    if (k_ === 1) {
      let q = D.qtext[r.qt[t] - 1];
      if (r.qt[t] === 4 && r.cand && r.cand[t] >= 0) q = "Is the " + instName(sc, r.cand[t]) + " the target?";
      dec += ": \u201c" + q + "\u201d";
    }
    detail.append(h("p", {cls: "decision", text: "Step " + t + ": " + dec}));
    const oracle = text => h("p", {cls: "oracle"}, h("b", {text: "Oracle: "}), text);
    if (k_ === 1 && r.ans[t]) detail.append(oracle(r.ans[t]));
    if (k_ === 0) {
      const [x1, y1] = P(t + 1), [x0, y0] = P(t);
      detail.append(h("p", {text: "Moved to (" + f2(x1) + ", " + f2(y1) + "), " + f2(Math.hypot(x1 - x0, y1 - y0)) + " m from where it decided."}));
      if (r.bl) { const b = []; for (let j = 0; j < 8; j++) if (r.bl[t] & (1 << j)) b.push(D.views[j]);
        detail.append(h("p", {text: "Blocked headings: " + (b.length ? b.join(", ") + " (relative to the heading before the move)" : "none")})); }
      if (r.hp && r.hp[t] > 0) detail.append(oracle(D.hint[r.hp[t]]));
    }
    if (r.dc) { const c = r.nq.slice(4 * t, 4 * t + 4);
      detail.append(h("p", {text: "Cost discount after this step: " + f3(r.dc[t]) + " (charged " + c.map((v, j) => "Q" + (j + 1) + " " + v).join(", ") + ")"})); }
    const obs = h("div", {cls: "obs"});
    if (r.rl || r.vis) {
      obs.append(h("p", {cls: "muted", text: "Observation when deciding: in the " + (r.rl && r.rl[t] >= 0 ? D.rooms[r.rl[t]] : "(no room)") +
        (D.noise ? "; perception noise on, perceived attributes shown where they differ" : "")}));
      const ul = h("ul", {cls: "visible"});
      const [px, py] = P(t);
      for (const v of (r.vis ? r.vis[t] : [])) {
        const hnd = Array.isArray(v) ? v[0] : v, it = sc.inst[hnd];
        if (!it) continue;
        const dist = Math.hypot(it[5] - px, it[6] - py), rel = Math.atan2(it[6] - py, it[5] - px) - yaw;
        const perceived = Array.isArray(v) ? " [perceived: " + attrWords(v.slice(1)) + "]" : "";
        const li = h("li", {text: instName(sc, hnd) + perceived + ": " + f2(dist) + " m, " + viewOf(rel) +
          (hnd === ep.target ? "  \u2190 target" : ep.distr.includes(hnd) ? "  \u2190 distractor" : "")});
        ul.append(li);
      }
      if (!ul.childElementCount) ul.append(h("li", {cls: "muted", text: "no instance in sight"}));
      obs.append(ul);
    }
    const im = r.img && r.img[String(t)];
    if (im) {
      const box = h("div", {cls: "images"});
      if (im[0]) box.append(h("figure", {}, h("img", {src: im[0], alt: "panel at step " + t}), h("figcaption", {text: "Planner panel"})));
      if (im[1]) {
        const wrap = h("div", {cls: "grounder"}, h("img", {src: im[1], alt: "Grounder view at step " + t}));
        if (k_ === 0 && r.c) wrap.append(h("div", {cls: "cell", style: "left:" + (r.c[t] - 1) * 12.5 + "%;top:" + (8 - r.r[t]) * 12.5 + "%;width:12.5%;height:12.5%"}));
        box.append(h("figure", {}, wrap, h("figcaption", {text: "Grounder view" + (k_ === 0 && r.c ? ", chosen cell col " + r.c[t] + ", row " + r.r[t] : "")})));
      }
      detail.append(box);
    }
    detail.append(obs);
    for (const c of (r.tx && r.tx[String(t)]) || []) {
      const retries = Array.isArray(c.retries) ? c.retries : [];
      const n_retry = Array.isArray(c.retries) ? c.retries.length : c.retries;
      const box = h("div", {cls: "call", "data-role": c.role},
        h("p", {cls: "decision", text: c.role + " call" + (n_retry ? ", " + n_retry + " retr" + (n_retry === 1 ? "y" : "ies") : "")}),
        h("details", {}, h("summary", {text: "prompt (" + c.prompt.length + " characters)"}), h("pre", {cls: "prompt", text: c.prompt})),
        h("p", {text: "raw reply:"}), h("pre", {cls: "reply", text: c.reply}),
        h("p", {text: "parsed:"}), h("pre", {cls: "parsed", text: JSON.stringify(c.parsed, null, 1)}));
      if (c.rule) box.append(h("p", {cls: "rule", text: "rule: " + c.rule + (c.text ? ": " + c.text : "")}));
      retries.forEach((x, j) => box.append(h("p", {cls: "muted", text: "retry " + (j + 1) + ": " + (x.error || "")}), h("pre", {text: x.reply || ""})));
      if (c.error) box.append(h("p", {cls: "error", text: "error: " + c.error}));
      detail.append(box);
    }
  }
  set(0);
  return root;
}

function showEpisode(i, a, b) {
  document.getElementById("index-view").hidden = true;
  const view = document.getElementById("episode-view");
  view.hidden = false;
  const ep = E[i], head = document.getElementById("episode-head"), panels = document.getElementById("panels");
  const vis = visibleOrder(), at = vis.indexOf(i);
  const agentSel = (id, cur, none) => {
    const s_ = h("select", {id: id});
    if (none) s_.append(h("option", {value: "", text: "\u2014"}));
    A.forEach(x => s_.append(h("option", {value: x, text: x})));
    s_.value = cur || "";
    s_.addEventListener("change", () => route(i, document.getElementById("sel-a").value, document.getElementById("sel-b").value));
    return s_;
  };
  const nav = (j, t) => { const x = h("button", {text: t, onclick: () => route(vis[j], a, b)});
    x.disabled = at < 0 || j < 0 || j >= vis.length; return x; };
  const prev = nav(at - 1, "\u2190 previous"), next = nav(at + 1, "next \u2192");
  head.replaceChildren(
    h("div", {cls: "nav"}, h("a", {href: "#", text: "\u2190 index"}), prev, next,
      h("label", {}, "agent ", agentSel("sel-a", a, false)), h("label", {}, "compare with ", agentSel("sel-b", b, true))),
    h("h2", {}, ep.id + " ", h("span", {cls: ep.diff, text: "(" + ep.diff + ")"}), " in " + ep.scene),
    h("p", {cls: "facts", text: ep.instr + " Target: " + ep.cat + " in the " + ep.room + "."}),
    h("p", {cls: "facts", text: "Description (the oracle's Type-1 answer): " + ep.desc}),
    h("p", {cls: "facts", text: "Region (the oracle's Type-2 answer): " + ep.region}));
  panels.replaceChildren(...[a, b].filter(x => x && A.includes(x)).map((x, slot) => Panel(i, A.indexOf(x), slot)));
  document.title = ep.id + " \u2014 " + D.title;
}
function showIndex() {
  document.getElementById("episode-view").hidden = true;
  document.getElementById("index-view").hidden = false;
  document.getElementById("panels").replaceChildren();
  document.title = D.title + ": ignjax episodes";
}
function route_() {
  const p = new URLSearchParams(location.hash.slice(1));
  const i = p.has("ep") ? parseInt(p.get("ep"), 10) : NaN;
  if (Number.isInteger(i) && i >= 0 && i < E.length) {
    const a = A.includes(p.get("a")) ? p.get("a") : A[0], b = A.includes(p.get("b")) && p.get("b") !== a ? p.get("b") : null;
    showEpisode(i, a, b);
  } else showIndex();
}
buildFilters();
buildIndex();
applyFilters();
window.addEventListener("hashchange", route_);
route_();
document.body.dataset.ready = String(Math.round(performance.now()));  // ms from navigation start to a built page
})();
"""

__all__ = ["SCRIPT"]
