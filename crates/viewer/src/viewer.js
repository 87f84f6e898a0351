"use strict";

// Render status for automated checks: "rendered" once the first frame is drawn, "error: ..." on
// any uncaught error or rejection (which is also shown on the page).
function reportError(message) {
  document.body.dataset.status = "error: " + message;
  const box = document.getElementById("error");
  if (box) {
    box.hidden = false;
    box.textContent = "Viewer error: " + message;
  }
}
window.onerror = function (message) {
  reportError(String(message));
  return false;
};
window.addEventListener("unhandledrejection", function (event) {
  const reason = event.reason;
  reportError("unhandled rejection: " + (reason && reason.message ? reason.message : String(reason)));
});

(function () {
  // ---------------------------------------------------------------- palette
  const LINK_COLOUR = "#e07b39";
  const LINK_EDGE = "#9c4f1f";
  const LINK_SHINE = "#f6b88c";
  const PEN_COLOUR = "#d7263d";
  const PEN_EDGE = "#8a1322";
  const PEN_SHINE = "#f58a97";
  const JOINT_COLOUR = "#1d2430";
  const LINE_COLOUR = "#1f9d55";
  const CONE_FILL = "rgba(236, 180, 20, 0.16)";
  const CONE_EDGE = "rgba(176, 128, 0, 0.75)";
  const AXIS_COLOUR = "#6a3fb5";
  const AXIS_OUT_COLOUR = "#b3261e";
  const GRID_COLOUR = "#d3d9e2";
  const SHADOW_COLOUR = "rgba(30, 40, 60, 0.10)";
  const SURFACE_FILL = "rgba(150, 110, 70, 0.16)";
  const SURFACE_EDGE = "rgba(120, 85, 50, 0.35)";
  const OBSTACLE_FILL = "rgba(90, 105, 130, 0.30)";
  const OBSTACLE_EDGE = "rgba(50, 60, 80, 0.75)";
  const OBSTACLE_SHINE = "rgba(220, 228, 240, 0.55)";
  // Planes (the work surface, half-spaces) are drawn as patches of square tiles this wide, so
  // that painter's order sorts them among the links.
  const TILE = 0.1;
  const CONTROLLER_COLOURS = {
    classical: "#2b6cb0",
    learned: "#d53f8c",
    search: "#dd6b20",
    none: "#9aa3af",
  };
  const CONTROLLER_LABELS = {
    classical: "classical controller",
    learned: "learned policy",
    search: "search detour",
    none: "no command (last step)",
  };

  const FOV = (40 * Math.PI) / 180;
  const NEAR = 0.02;
  const CONE_LENGTH = 0.15;
  const PIECE_LENGTH = 0.05;

  // ---------------------------------------------------------------- vectors
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const scale = (a, k) => [a[0] * k, a[1] * k, a[2] * k];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [
    a[1] * b[2] - a[2] * b[1],
    a[2] * b[0] - a[0] * b[2],
    a[0] * b[1] - a[1] * b[0],
  ];
  const norm = (a) => Math.sqrt(dot(a, a));
  const unit = (a) => {
    const l = norm(a);
    return l > 0 ? scale(a, 1 / l) : [0, 0, 1];
  };
  const mix = (a, b, f) => a + (b - a) * f;
  const mix3 = (a, b, f) => [mix(a[0], b[0], f), mix(a[1], b[1], f), mix(a[2], b[2], f)];
  const perpendicular = (n) => unit(cross(n, Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0]));

  // ---------------------------------------------------------------- data
  const data = JSON.parse(document.getElementById("motion-data").textContent);
  const steps = data.steps;
  if (!Array.isArray(steps) || steps.length === 0) {
    throw new Error("the motion data holds no steps");
  }
  const last = steps.length - 1;
  const duration = steps[last].t;
  const task = data.task;
  const thetaMax = data.constraints.theta_max_deg;
  const tolerance = data.constraints.line_tolerance_m;
  const lateralDir = unit(cross(task.n, task.d));
  const coneU = perpendicular(task.n);
  const coneV = cross(task.n, coneU);
  // A path task's path, sampled every path.step_m of arc length; undefined for a line.
  const path = task.path;
  // The point at progress (arc length) s and the unit direction across the task there.
  function alongTask(s) {
    if (!path) return { point: add(task.p0, scale(task.d, s)), side: lateralDir };
    const last = path.points.length - 1;
    const x = Math.min(Math.max(s / path.step_m, 0), last);
    const i = Math.min(Math.floor(x), Math.max(last - 1, 0));
    const f = Math.min(1, x - i);
    const j = Math.min(i + 1, last);
    return { point: mix3(path.points[i], path.points[j], f), side: unit(mix3(path.sides[i], path.sides[j], f)) };
  }
  const onLine = (s) => alongTask(s).point;

  let sMin = 0;
  let sMax = 0;
  for (const step of steps) {
    sMin = Math.min(sMin, step.s);
    sMax = Math.max(sMax, step.s);
  }
  // A line is drawn a bit beyond the planned range; a path to its end.
  const extension = path ? 0 : Math.max(0.05, 0.15 * (sMax - sMin));
  const sEnd = path ? path.length_m : sMax + extension;

  // The last step at or before time t (timestamps need not be uniform).
  function stepAt(t) {
    if (t >= steps[last].t) return last;
    let lo = 0;
    let hi = last;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (steps[mid].t <= t) lo = mid;
      else hi = mid;
    }
    return lo;
  }

  // The arm at time t, interpolated between the recorded steps around it.
  function frameAt(t) {
    const index = stepAt(t);
    const a = steps[index];
    const b = steps[Math.min(index + 1, last)];
    const span = b.t - a.t;
    const f = span > 0 ? Math.min(1, Math.max(0, (t - a.t) / span)) : 0;
    const joints = a.joints.map((p, k) => mix3(p, b.joints[k], f));
    return {
      index,
      f,
      s: mix(a.s, b.s, f),
      lateral: mix(a.lateral, b.lateral, f),
      angle: mix(a.tool_angle_deg, b.tool_angle_deg, f),
      rho: mix(a.rho, b.rho, f),
      controller: a.controller,
      joints,
      tcp: joints[joints.length - 1],
      axis: unit(mix3(a.tool_axis, b.tool_axis, f)),
      capsules: a.capsules.map((c, k) => {
        const d = b.capsules[k];
        return [
          mix3(c.slice(0, 3), d.slice(0, 3), f),
          mix3(c.slice(3, 6), d.slice(3, 6), f),
        ];
      }),
    };
  }

  // ---------------------------------------------------------------- bounds and view
  const bounds = { lo: [Infinity, Infinity, Infinity], hi: [-Infinity, -Infinity, -Infinity] };
  function include(p, margin) {
    for (let k = 0; k < 3; k++) {
      bounds.lo[k] = Math.min(bounds.lo[k], p[k] - margin);
      bounds.hi[k] = Math.max(bounds.hi[k], p[k] + margin);
    }
  }
  const largestRadius = data.capsules.reduce((r, c) => Math.max(r, c.radius), 0);
  for (const step of steps) {
    for (const c of step.capsules) {
      include(c.slice(0, 3), largestRadius);
      include(c.slice(3, 6), largestRadius);
    }
  }
  include(onLine(sMin - extension), 0);
  include(onLine(sEnd), 0);
  if (path) for (const p of path.points) include(p, 0);
  include([0, 0, 0], 0);
  const centre = scale(add(bounds.lo, bounds.hi), 0.5);
  const radius = Math.max(0.2, 0.5 * norm(sub(bounds.hi, bounds.lo)));

  const view = { yaw: 0, pitch: 0, distance: 1, target: centre };
  function resetView() {
    // Look across the line (perpendicular to d), from the side of the task, a little ahead.
    const h = [task.d[0], task.d[1]];
    let yaw = -Math.PI / 3;
    if (Math.hypot(h[0], h[1]) > 0.2) {
      let side = [-h[1], h[0]];
      if (side[0] * task.p0[0] + side[1] * task.p0[1] < 0) side = [h[1], -h[0]];
      yaw = Math.atan2(side[1], side[0]) - 0.45 * Math.sign(side[0] * h[1] - side[1] * h[0]);
    }
    view.yaw = yaw;
    view.pitch = 0.38;
    view.distance = (0.9 * radius) / Math.sin(FOV / 2);
    view.target = centre;
  }
  resetView();

  // ---------------------------------------------------------------- canvas
  const canvas = document.getElementById("scene");
  const ctx = canvas.getContext("2d");
  const timeline = document.getElementById("timeline");
  const tctx = timeline.getContext("2d");
  let width = 800;
  let height = 500;

  function fitCanvas(c, context) {
    const ratio = window.devicePixelRatio || 1;
    const w = Math.max(1, c.clientWidth || c.width);
    const h = Math.max(1, c.clientHeight || c.height);
    c.width = Math.round(w * ratio);
    c.height = Math.round(h * ratio);
    context.setTransform(ratio, 0, 0, ratio, 0, 0);
    return [w, h];
  }
  function resize() {
    [width, height] = fitCanvas(canvas, ctx);
    fitCanvas(timeline, tctx);
  }

  function camera() {
    const cp = Math.cos(view.pitch);
    const back = [cp * Math.cos(view.yaw), cp * Math.sin(view.yaw), Math.sin(view.pitch)];
    const forward = scale(back, -1);
    const right = unit(cross(forward, [0, 0, 1]));
    return {
      eye: add(view.target, scale(back, view.distance)),
      forward,
      right,
      up: cross(right, forward),
      focal: (0.5 * height) / Math.tan(FOV / 2),
    };
  }
  function project(cam, p) {
    const v = sub(p, cam.eye);
    const z = dot(v, cam.forward);
    if (z < NEAR) return null;
    return {
      x: width / 2 + (cam.focal * dot(v, cam.right)) / z,
      y: height / 2 - (cam.focal * dot(v, cam.up)) / z,
      z,
    };
  }

  // ---------------------------------------------------------------- drawing
  function stroke(a, b, lineWidth, colour) {
    ctx.strokeStyle = colour;
    ctx.lineWidth = lineWidth;
    ctx.beginPath();
    ctx.moveTo(a.x, a.y);
    ctx.lineTo(b.x, b.y);
    ctx.stroke();
  }
  function disc(p, r, fill, edge) {
    ctx.beginPath();
    ctx.arc(p.x, p.y, r, 0, 2 * Math.PI);
    ctx.fillStyle = fill;
    ctx.fill();
    if (edge) {
      ctx.lineWidth = 1.5;
      ctx.strokeStyle = edge;
      ctx.stroke();
    }
  }

  // A capsule seen in perspective: the outline of two discs (radii ra, rb) and their outer
  // tangents, filled, edged, with a highlight along its axis.
  function drawCapsule(a, ra, b, rb, [body, edge, shine]) {
    const dx = b.x - a.x;
    const dy = b.y - a.y;
    const distance = Math.hypot(dx, dy);
    ctx.beginPath();
    if (distance <= Math.abs(ra - rb) + 1e-6) {
      const [c, r] = ra >= rb ? [a, ra] : [b, rb];
      ctx.arc(c.x, c.y, r, 0, 2 * Math.PI);
    } else {
      const along = Math.atan2(dy, dx);
      const half = Math.acos((ra - rb) / distance);
      ctx.arc(a.x, a.y, ra, along + half, along + 2 * Math.PI - half);
      ctx.arc(b.x, b.y, rb, along - half, along + half);
      ctx.closePath();
    }
    ctx.fillStyle = body;
    ctx.fill();
    ctx.lineWidth = 1.5;
    ctx.strokeStyle = edge;
    ctx.stroke();
    const o = -0.35;
    stroke({ x: a.x + o * ra, y: a.y + o * ra }, { x: b.x + o * rb, y: b.y + o * rb }, 0.25 * (ra + rb), shine);
  }

  // A planar polygon (world corners), filled and edged, queued at its mean depth.
  function queuePolygon(cam, queue, corners, fill, edge) {
    const projected = corners.map((c) => project(cam, c));
    if (projected.some((p) => !p)) return;
    const depth = projected.reduce((sum, p) => sum + p.z, 0) / projected.length;
    queue(depth, () => {
      ctx.beginPath();
      ctx.moveTo(projected[0].x, projected[0].y);
      for (const p of projected.slice(1)) ctx.lineTo(p.x, p.y);
      ctx.closePath();
      ctx.fillStyle = fill;
      ctx.fill();
      ctx.lineWidth = 0.8;
      ctx.strokeStyle = edge;
      ctx.stroke();
    });
  }

  // The patch of the plane through `origin` spanned by unit vectors u, v over [u0, u1] x [v0, v1],
  // as square tiles.
  function queuePlane(cam, queue, origin, u, v, [u0, u1], [v0, v1], fill, edge) {
    const nu = Math.max(1, Math.ceil((u1 - u0) / TILE));
    const nv = Math.max(1, Math.ceil((v1 - v0) / TILE));
    const at = (a, b) => add(origin, add(scale(u, a), scale(v, b)));
    for (let i = 0; i < nu; i++) {
      for (let j = 0; j < nv; j++) {
        const a0 = mix(u0, u1, i / nu);
        const a1 = mix(u0, u1, (i + 1) / nu);
        const b0 = mix(v0, v1, j / nv);
        const b1 = mix(v0, v1, (j + 1) / nv);
        queuePolygon(cam, queue, [at(a0, b0), at(a1, b0), at(a1, b1), at(a0, b1)], fill, edge);
      }
    }
  }

  // The work surface around the line and the obstacles of the cell.
  const BOX_FACES = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]];
  function queueCell(cam, queue) {
    if (data.constraints.work_surface) {
      const margin = extension + 0.1;
      queuePlane(cam, queue, task.p0, task.d, lateralDir, [sMin - margin, sMax + margin], [-0.2, 0.2],
        SURFACE_FILL, SURFACE_EDGE);
    }
    const middle = scale(add(bounds.lo, bounds.hi), 0.5);
    const half = Math.max(0.4, 0.6 * norm(sub(bounds.hi, bounds.lo)));
    for (const obstacle of data.obstacles) {
      if (obstacle.kind === "half_space") {
        const u = perpendicular(obstacle.normal);
        const v = cross(obstacle.normal, u);
        const foot = sub(middle, scale(obstacle.normal, dot(sub(middle, obstacle.point), obstacle.normal)));
        queuePlane(cam, queue, foot, u, v, [-half, half], [-half, half], OBSTACLE_FILL, OBSTACLE_EDGE);
      } else if (obstacle.kind === "box") {
        for (const face of BOX_FACES) {
          queuePolygon(cam, queue, face.map((k) => obstacle.corners[k]), OBSTACLE_FILL, OBSTACLE_EDGE);
        }
      } else {
        const [a, b] = obstacle.kind === "sphere" ? [obstacle.centre, obstacle.centre] : [obstacle.start, obstacle.end];
        const pa = project(cam, a);
        const pb = project(cam, b);
        if (!(pa && pb)) continue;
        const ra = (obstacle.radius * cam.focal) / pa.z;
        const rb = (obstacle.radius * cam.focal) / pb.z;
        queue((pa.z + pb.z) / 2, () => drawCapsule(pa, ra, pb, rb, [OBSTACLE_FILL, OBSTACLE_EDGE, OBSTACLE_SHINE]));
      }
    }
  }

  // Splits the segment a-b into pieces no longer than `piece` so painter's order sorts them
  // well; calls emit(pa, pb, depth) with projected ends.
  function pieces(cam, a, b, piece, emit) {
    const n = Math.max(1, Math.min(12, Math.ceil(norm(sub(b, a)) / piece)));
    let previous = a;
    for (let k = 1; k <= n; k++) {
      const next = mix3(a, b, k / n);
      const pa = project(cam, previous);
      const pb = project(cam, next);
      if (pa && pb) emit(pa, pb, (pa.z + pb.z) / 2);
      previous = next;
    }
  }

  function drawFloor(cam, frame) {
    const step = 0.1;
    const x0 = Math.floor(bounds.lo[0] / step) * step;
    const x1 = Math.ceil(bounds.hi[0] / step) * step;
    const y0 = Math.floor(bounds.lo[1] / step) * step;
    const y1 = Math.ceil(bounds.hi[1] / step) * step;
    ctx.lineCap = "butt";
    for (let x = x0; x <= x1 + 1e-9; x += step) {
      pieces(cam, [x, y0, 0], [x, y1, 0], 0.25, (a, b) => stroke(a, b, 1, GRID_COLOUR));
    }
    for (let y = y0; y <= y1 + 1e-9; y += step) {
      pieces(cam, [x0, y, 0], [x1, y, 0], 0.25, (a, b) => stroke(a, b, 1, GRID_COLOUR));
    }
    ctx.lineCap = "round";
    frame.capsules.forEach(([a, b], k) => {
      const r = data.capsules[k].radius;
      const pa = project(cam, [a[0], a[1], 0]);
      const pb = project(cam, [b[0], b[1], 0]);
      if (pa && pb) stroke(pa, pb, (2 * r * cam.focal) / ((pa.z + pb.z) / 2), SHADOW_COLOUR);
    });
  }

  function drawScene(cam, frame) {
    const items = [];
    const queue = (depth, draw) => items.push({ depth, draw });

    // Task line or path: the planned range solid, the rest faint; the tolerance on each side;
    // the start marked. A path is drawn piece by piece between its samples.
    const lineSegment = (s0, s1, lineWidth, colour, offset = 0) => {
      const cuts = [s0];
      if (path) for (let s = Math.ceil(s0 / path.step_m) * path.step_m; s < s1; s += path.step_m) if (s > s0) cuts.push(s);
      cuts.push(s1);
      for (let k = 0; k + 1 < cuts.length; k++) {
        const [a, b] = [alongTask(cuts[k]), alongTask(cuts[k + 1])];
        pieces(cam, add(a.point, scale(a.side, offset)), add(b.point, scale(b.side, offset)), PIECE_LENGTH,
          (pa, pb, z) => queue(z, () => stroke(pa, pb, lineWidth, colour)));
      }
    };
    lineSegment(sMin - extension, sMin, 1.5, "rgba(31, 157, 85, 0.45)");
    lineSegment(sMin, sMax, 3, LINE_COLOUR);
    lineSegment(sMax, sEnd, 1.5, "rgba(31, 157, 85, 0.45)");
    for (const sign of [-1, 1]) lineSegment(sMin, sMax, 1, "rgba(31, 157, 85, 0.35)", sign * tolerance);
    const start = project(cam, task.p0);
    if (start) {
      queue(start.z - 0.01, () => {
        disc(start, 6, LINE_COLOUR, "#ffffff");
        ctx.fillStyle = "#145c33";
        ctx.font = "12px system-ui, sans-serif";
        ctx.fillText("p0", start.x + 9, start.y - 7);
      });
    }
    queueCell(cam, queue);

    // Tolerance ring around the line (path) at the TCP's foot point.
    const { point: foot, side } = alongTask(frame.s);
    const ring = [];
    for (let k = 0; k <= 32; k++) {
      const phi = (2 * Math.PI * k) / 32;
      ring.push(add(foot, add(scale(side, tolerance * Math.cos(phi)), scale(task.n, tolerance * Math.sin(phi)))));
    }
    for (let k = 0; k < 32; k++) {
      const a = project(cam, ring[k]);
      const b = project(cam, ring[k + 1]);
      if (a && b) queue((a.z + b.z) / 2, () => stroke(a, b, 1.2, "rgba(31, 157, 85, 0.7)"));
    }

    // TCP trace so far, coloured by the controller that drove each step.
    const trace = steps.slice(0, frame.index + 1).map((s) => s.joints[s.joints.length - 1]);
    trace.push(frame.tcp);
    for (let k = 0; k + 1 < trace.length; k++) {
      const colour = CONTROLLER_COLOURS[steps[k].controller || "none"];
      const a = project(cam, trace[k]);
      const b = project(cam, trace[k + 1]);
      if (a && b) queue((a.z + b.z) / 2 - 0.02, () => stroke(a, b, 4, colour));
    }

    // Capsules: body with outline and shine; the pen in its own colour.
    frame.capsules.forEach(([a, b], k) => {
      const capsule = data.capsules[k];
      const pa = project(cam, a);
      const pb = project(cam, b);
      if (!(pa && pb)) return;
      const colours = capsule.pen ? [PEN_COLOUR, PEN_EDGE, PEN_SHINE] : [LINK_COLOUR, LINK_EDGE, LINK_SHINE];
      const ra = (capsule.radius * cam.focal) / pa.z;
      const rb = (capsule.radius * cam.focal) / pb.z;
      queue((pa.z + pb.z) / 2, () => drawCapsule(pa, ra, pb, rb, colours));
    });

    // Joint origins, drawn over the links that carry them.
    frame.joints.slice(0, -1).forEach((p) => {
      const q = project(cam, p);
      if (q) queue(q.z - 0.08, () => disc(q, 4, JOINT_COLOUR, "#ffffff"));
    });
    const tcp = project(cam, frame.tcp);
    if (tcp) queue(tcp.z - 0.03, () => disc(tcp, 4.5, PEN_COLOUR, "#ffffff"));

    // Tool cone: half-angle theta_max around n, apex at the TCP, opening back along the pen.
    const apex = frame.tcp;
    const coneRadius = CONE_LENGTH * Math.tan((thetaMax * Math.PI) / 180);
    const base = sub(apex, scale(task.n, CONE_LENGTH));
    const rim = [];
    for (let k = 0; k <= 36; k++) {
      const phi = (2 * Math.PI * k) / 36;
      rim.push(add(base, add(scale(coneU, coneRadius * Math.cos(phi)), scale(coneV, coneRadius * Math.sin(phi)))));
    }
    const pApex = project(cam, apex);
    for (let k = 0; k < 36; k++) {
      const a = project(cam, rim[k]);
      const b = project(cam, rim[k + 1]);
      if (!(a && b && pApex)) continue;
      queue((a.z + b.z + pApex.z) / 3, () => {
        ctx.beginPath();
        ctx.moveTo(pApex.x, pApex.y);
        ctx.lineTo(a.x, a.y);
        ctx.lineTo(b.x, b.y);
        ctx.closePath();
        ctx.fillStyle = CONE_FILL;
        ctx.fill();
        stroke(a, b, 1.2, CONE_EDGE);
        if (k % 9 === 0) stroke(pApex, a, 0.8, CONE_EDGE);
      });
    }

    // Tool axis through the TCP: along the pen and a little beyond the tip.
    const axisColour = frame.angle > thetaMax ? AXIS_OUT_COLOUR : AXIS_COLOUR;
    pieces(cam, sub(apex, scale(frame.axis, 1.1 * CONE_LENGTH)), add(apex, scale(frame.axis, 0.45 * CONE_LENGTH)),
      0.03, (a, b, z) => queue(z - 0.04, () => stroke(a, b, 2, axisColour)));

    items.sort((p, q) => q.depth - p.depth);
    ctx.lineCap = "round";
    for (const item of items) item.draw();
  }

  function drawBackground() {
    const gradient = ctx.createLinearGradient(0, 0, 0, height);
    gradient.addColorStop(0, "#f9fbfd");
    gradient.addColorStop(1, "#dfe5ee");
    ctx.fillStyle = gradient;
    ctx.fillRect(0, 0, width, height);
  }

  function drawTimeline() {
    const w = timeline.clientWidth;
    const h = timeline.clientHeight;
    tctx.clearRect(0, 0, w, h);
    const x = (t) => (duration > 0 ? (t / duration) * w : 0);
    if (duration > 0) {
      // One bar per run of steps driven by the same controller.
      let from = 0;
      for (let k = 1; k <= last; k++) {
        const acting = steps[from].controller;
        if (k < last && steps[k].controller === acting) continue;
        tctx.fillStyle = CONTROLLER_COLOURS[acting || "none"];
        tctx.fillRect(x(steps[from].t), 0, Math.max(1, x(steps[k].t) - x(steps[from].t)), h);
        from = k;
      }
    } else {
      tctx.fillStyle = CONTROLLER_COLOURS[steps[0].controller || "none"];
      tctx.fillRect(0, 0, w, h);
    }
    tctx.fillStyle = "#1d2430";
    tctx.fillRect(Math.min(w - 2, Math.max(0, x(current) - 1)), 0, 2, h);
  }

  // ---------------------------------------------------------------- readout
  const text = (id, value) => {
    document.getElementById(id).textContent = value;
  };
  function showReadout(frame) {
    text("r-time", current.toFixed(2) + " s of " + duration.toFixed(2) + " s");
    // Of the plan's length on a line, of the whole path on a path task.
    const total = path ? path.length_m : data.path_length_m;
    const percent = total > 0 ? " (" + Math.round((100 * frame.s) / total) + " %)" : "";
    text("r-path", frame.s.toFixed(3) + " m of " + total.toFixed(3) + " m" + percent);
    text("r-lateral", (1000 * frame.lateral).toFixed(1) + " mm (limit " + (1000 * tolerance).toFixed(1) + " mm)");
    const angle = document.getElementById("r-angle");
    angle.textContent = frame.angle.toFixed(1) + "\u00b0 (limit " + thetaMax.toFixed(1) + "\u00b0)";
    angle.classList.toggle("limit", frame.angle >= 0.9 * thetaMax);
    text("r-rho", frame.rho.toFixed(3));
    const acting = frame.controller ? CONTROLLER_LABELS[frame.controller] : CONTROLLER_LABELS.none;
    text("r-step", frame.index + " of " + last + ", " + acting);
  }

  function buildLegend() {
    const legend = document.getElementById("legend");
    const entry = (colour, label) => {
      const item = document.createElement("span");
      const swatch = document.createElement("span");
      swatch.className = "swatch";
      swatch.style.background = colour;
      item.append(swatch, label);
      legend.append(item);
    };
    const present = new Set(steps.map((s) => s.controller || "none"));
    for (const key of ["classical", "learned", "search", "none"]) {
      if (present.has(key)) entry(CONTROLLER_COLOURS[key], CONTROLLER_LABELS[key]);
    }
    entry(LINK_COLOUR, "links");
    entry(PEN_COLOUR, "pen / TCP");
    entry(LINE_COLOUR, path ? "task path and tolerance" : "task line (p0 + s\u00b7d) and tolerance");
    entry(CONE_EDGE, "tool cone (" + thetaMax + "\u00b0 about n)");
    entry(AXIS_COLOUR, "tool axis");
    if (data.constraints.work_surface) entry(SURFACE_EDGE, "work surface (only the pen may touch it)");
    if (data.obstacles.length > 0) {
      entry(OBSTACLE_EDGE, "obstacles: " + data.obstacles.map((o) => o.name).join(", "));
    }
  }

  // ---------------------------------------------------------------- playback
  const playButton = document.getElementById("play");
  const speedSelect = document.getElementById("speed");
  const scrub = document.getElementById("scrub");
  let current = 0;
  let playing = duration > 0;
  let dirty = true;
  let previousNow = null;
  let scrubbing = false;

  scrub.min = "0";
  scrub.max = String(duration);
  scrub.step = "any";

  function setPlaying(on) {
    playing = on && duration > 0;
    if (playing && current >= duration) current = 0;
    playButton.textContent = playing ? "Pause" : "Play";
    previousNow = null;
    dirty = true;
  }
  function draw() {
    const frame = frameAt(current);
    const cam = camera();
    drawBackground();
    drawFloor(cam, frame);
    drawScene(cam, frame);
    drawTimeline();
    showReadout(frame);
    if (!scrubbing) scrub.value = String(current);
  }
  function tick(now) {
    if (playing) {
      if (previousNow !== null) current += ((now - previousNow) / 1000) * Number(speedSelect.value);
      previousNow = now;
      if (current >= duration) {
        current = duration;
        setPlaying(false);
      }
      dirty = true;
    }
    if (dirty) {
      dirty = false;
      draw();
    }
    window.requestAnimationFrame(tick);
  }

  playButton.addEventListener("click", () => setPlaying(!playing));
  speedSelect.addEventListener("change", () => {
    previousNow = null;
  });
  // Scrubbing redraws at once, so the scene and the read-out follow the bar without waiting for
  // the next animation frame.
  scrub.addEventListener("input", () => {
    scrubbing = true;
    current = Math.min(duration, Math.max(0, Number(scrub.value)));
    previousNow = null;
    draw();
    dirty = false;
  });
  scrub.addEventListener("change", () => {
    scrubbing = false;
  });
  document.addEventListener("keydown", (event) => {
    const tag = event.target && event.target.tagName;
    if (event.key === " " && tag !== "BUTTON" && tag !== "SELECT" && tag !== "INPUT") {
      event.preventDefault();
      setPlaying(!playing);
    }
  });

  // Orbit by dragging, zoom with the wheel, reset with a double click.
  let drag = null;
  canvas.addEventListener("pointerdown", (event) => {
    drag = { x: event.clientX, y: event.clientY };
    canvas.setPointerCapture(event.pointerId);
    canvas.classList.add("dragging");
  });
  canvas.addEventListener("pointermove", (event) => {
    if (!drag) return;
    view.yaw -= (event.clientX - drag.x) * 0.008;
    view.pitch = Math.min(1.5, Math.max(-1.5, view.pitch + (event.clientY - drag.y) * 0.008));
    drag = { x: event.clientX, y: event.clientY };
    dirty = true;
  });
  const endDrag = () => {
    drag = null;
    canvas.classList.remove("dragging");
  };
  canvas.addEventListener("pointerup", endDrag);
  canvas.addEventListener("pointercancel", endDrag);
  canvas.addEventListener(
    "wheel",
    (event) => {
      event.preventDefault();
      const factor = Math.exp(Math.max(-1, Math.min(1, event.deltaY * 0.0015)));
      view.distance = Math.min(20 * radius, Math.max(0.3 * radius, view.distance * factor));
      dirty = true;
    },
    { passive: false },
  );
  canvas.addEventListener("dblclick", () => {
    resetView();
    dirty = true;
  });
  window.addEventListener("resize", () => {
    resize();
    dirty = true;
  });

  // ---------------------------------------------------------------- start
  text(
    "summary",
    data.robot + " \u00b7 " + last + " steps, " + duration.toFixed(2) + " s \u00b7 path length " +
      data.path_length_m.toFixed(3) + " m \u00b7 ended: " + data.termination,
  );
  buildLegend();
  // `page.html#t=0.6` opens paused at that share of the motion (a still, e.g. for a picture).
  const still = /(?:^#|&)t=([0-9.]+)/.exec(window.location.hash);
  if (still && Number.isFinite(Number(still[1]))) {
    current = Math.min(1, Math.max(0, Number(still[1]))) * duration;
    playing = false;
  }
  setPlaying(playing);
  resize();
  draw();
  dirty = false;
  if (!document.body.dataset.status.startsWith("error")) {
    document.body.dataset.status = "rendered";
  }
  window.requestAnimationFrame(tick);
})();
