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

// The core both pages run on (`emg`): the palette, vector algebra, a sampled path, and
// `emg.viewer(data)`, which animates the arm of `data.steps` in the cell of `data.obstacles`:
// perspective projection, painter's order, floor and shadows, capsules, tool cone and axis,
// the timeline, the read-out, the legend and the controls (play/pause, speed, scrubbing, orbit,
// zoom). A page adds its own drawing, read-out and timeline colours (`viewer.run(page)`).
const emg = (function () {
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

  // The index of the last of the ascending `values` at or before x (0 before the first).
  function lastAtOrBefore(values, x) {
    let lo = 0;
    let hi = values.length - 1;
    if (hi < 0 || x >= values[hi]) return Math.max(hi, 0);
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (values[mid] <= x) lo = mid;
      else hi = mid;
    }
    return lo;
  }

  // The point and the unit direction across the path in its surface at arc length s of a
  // sampled path ({length_m, s, points, sides}), interpolated between its samples.
  function alongPath(path, s) {
    const last = path.s.length - 1;
    const i = Math.min(lastAtOrBefore(path.s, s), Math.max(last - 1, 0));
    const j = Math.min(i + 1, last);
    const span = path.s[j] - path.s[i];
    const f = span > 0 ? Math.min(1, Math.max(0, (s - path.s[i]) / span)) : 0;
    return { point: mix3(path.points[i], path.points[j], f), side: unit(mix3(path.sides[i], path.sides[j], f)) };
  }

  // The page's data blob.
  function readData() {
    return JSON.parse(document.getElementById("motion-data").textContent);
  }

  // ---------------------------------------------------------------- the viewer
  // A viewer of the arm at `data.steps` (each {t, joints, tool_axis, capsules}, in time order)
  // among `data.capsules` and `data.obstacles`. Points the page draws besides the arm go into
  // the view's bounds with `include`; `run(page)` then starts it.
  function viewer(data) {
    const steps = data.steps;
    if (!Array.isArray(steps) || steps.length === 0) {
      throw new Error("the motion data holds no steps");
    }
    const last = steps.length - 1;
    const duration = steps[last].t;
    const times = steps.map((step) => step.t);

    // The last step at or before time t (timestamps need not be uniform).
    const stepAt = (t) => lastAtOrBefore(times, t);

    // The arm at time t, interpolated between the recorded steps around it; `a`, `b` and `f`
    // say between which steps and how far.
    function poseAt(t) {
      const index = stepAt(t);
      const a = steps[index];
      const b = steps[Math.min(index + 1, last)];
      const span = b.t - a.t;
      const f = span > 0 ? Math.min(1, Math.max(0, (t - a.t) / span)) : 0;
      const joints = a.joints.map((p, k) => mix3(p, b.joints[k], f));
      return {
        index,
        a,
        b,
        f,
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

    // -------------------------------------------------------------- bounds and view
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
    include([0, 0, 0], 0);
    let centre = [0, 0, 0];
    let radius = 1;

    // Looking across `along.d` (a horizontal direction of the work) from beyond `along.p0`,
    // a little ahead and above; or, given `back` (the unit direction from the target to the
    // eye), from there, turned a little for depth.
    let along = { p0: [1, 0, 0], d: [0, 1, 0] };
    let back = null;
    const view = { yaw: 0, pitch: 0, distance: 1, target: centre };
    function resetView() {
      const h = [along.d[0], along.d[1]];
      let yaw = -Math.PI / 3;
      let pitch = 0.38;
      if (back) {
        if (Math.hypot(back[0], back[1]) > 1e-6) yaw = Math.atan2(back[1], back[0]);
        yaw -= 0.35;
        pitch = Math.min(1.2, Math.max(-1.2, Math.asin(Math.max(-1, Math.min(1, back[2])))));
      } else if (Math.hypot(h[0], h[1]) > 0.2) {
        let side = [-h[1], h[0]];
        if (side[0] * along.p0[0] + side[1] * along.p0[1] < 0) side = [h[1], -h[0]];
        yaw = Math.atan2(side[1], side[0]) - 0.45 * Math.sign(side[0] * h[1] - side[1] * h[0]);
      }
      view.yaw = yaw;
      view.pitch = pitch;
      view.distance = (0.9 * radius) / Math.sin(FOV / 2);
      view.target = centre;
    }

    // -------------------------------------------------------------- canvas
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

    // -------------------------------------------------------------- drawing
    function stroke(a, b, lineWidth, colour) {
      ctx.strokeStyle = colour;
      ctx.lineWidth = lineWidth;
      ctx.beginPath();
      ctx.moveTo(a.x, a.y);
      ctx.lineTo(b.x, b.y);
      ctx.stroke();
    }
    // A dashed piece whose dash pattern continues `offset` pixels into a dashed line.
    function dashed(a, b, lineWidth, colour, offset) {
      ctx.setLineDash([7, 5]);
      ctx.lineDashOffset = offset;
      ctx.lineCap = "butt";
      stroke(a, b, lineWidth, colour);
      ctx.setLineDash([]);
      ctx.lineDashOffset = 0;
      ctx.lineCap = "round";
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
    function label(p, textValue, colour) {
      ctx.fillStyle = colour;
      ctx.font = "12px system-ui, sans-serif";
      ctx.fillText(textValue, p.x + 9, p.y - 7);
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
        const direction = Math.atan2(dy, dx);
        const half = Math.acos((ra - rb) / distance);
        ctx.arc(a.x, a.y, ra, direction + half, direction + 2 * Math.PI - half);
        ctx.arc(b.x, b.y, rb, direction - half, direction + half);
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

    // A planar polygon (world corners), filled and edged, queued at its mean depth, or at its
    // farthest corner's where it is `under` what lies on it (a work surface: a stroke or the
    // pen's tip anywhere on it is drawn over it).
    function queuePolygon(cam, queue, corners, fill, edge, under = false) {
      const projected = corners.map((c) => project(cam, c));
      if (projected.some((p) => !p)) return;
      const depth = under
        ? Math.max(...projected.map((p) => p.z))
        : projected.reduce((sum, p) => sum + p.z, 0) / projected.length;
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

    // The parallelogram of corners a, b, c, d (in turn), as tiles at most TILE wide, so that
    // painter's order sorts a large face among the links.
    function queueQuad(cam, queue, [a, b, c, d], fill, edge, under = false) {
      const nu = Math.max(1, Math.ceil(norm(sub(b, a)) / TILE));
      const nv = Math.max(1, Math.ceil(norm(sub(d, a)) / TILE));
      const at = (i, j) => mix3(mix3(a, b, i / nu), mix3(d, c, i / nu), j / nv);
      for (let i = 0; i < nu; i++) {
        for (let j = 0; j < nv; j++) {
          queuePolygon(cam, queue, [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)], fill, edge, under);
        }
      }
    }

    // The patch of the plane through `origin` spanned by unit vectors u, v over [u0, u1] x
    // [v0, v1], as square tiles.
    function queuePlane(cam, queue, origin, u, v, [u0, u1], [v0, v1], fill, edge, under = false) {
      const at = (a, b) => add(origin, add(scale(u, a), scale(v, b)));
      queueQuad(cam, queue, [at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1)], fill, edge, under);
    }

    // The solids of the cell: work surfaces (plates, half-spaces) in the surface's colours,
    // obstacles in theirs.
    const BOX_FACES = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]];
    function queueCell(cam, queue) {
      const middle = scale(add(bounds.lo, bounds.hi), 0.5);
      const half = Math.max(0.4, 0.6 * norm(sub(bounds.hi, bounds.lo)));
      for (const obstacle of data.obstacles) {
        const [fill, edge] = obstacle.surface ? [SURFACE_FILL, SURFACE_EDGE] : [OBSTACLE_FILL, OBSTACLE_EDGE];
        if (obstacle.kind === "half_space") {
          const u = perpendicular(obstacle.normal);
          const v = cross(obstacle.normal, u);
          const foot = sub(middle, scale(obstacle.normal, dot(sub(middle, obstacle.point), obstacle.normal)));
          queuePlane(cam, queue, foot, u, v, [-half, half], [-half, half], fill, edge, obstacle.surface);
        } else if (obstacle.kind === "box") {
          for (const face of BOX_FACES) {
            queueQuad(cam, queue, face.map((k) => obstacle.corners[k]), fill, edge, obstacle.surface);
          }
        } else {
          const [a, b] = obstacle.kind === "sphere" ? [obstacle.centre, obstacle.centre] : [obstacle.start, obstacle.end];
          const pa = project(cam, a);
          const pb = project(cam, b);
          if (!(pa && pb)) continue;
          const ra = (obstacle.radius * cam.focal) / pa.z;
          const rb = (obstacle.radius * cam.focal) / pb.z;
          queue((pa.z + pb.z) / 2, () => drawCapsule(pa, ra, pb, rb, [fill, edge, OBSTACLE_SHINE]));
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

    // The curve along(s) = {point, side} from s0 to s1, cut at the arc lengths `knots`
    // (ascending) and offset sideways, queued in pieces.
    function queueCurve(cam, queue, curve, knots, s0, s1, lineWidth, colour, offset = 0) {
      const cuts = [s0];
      for (let k = lastAtOrBefore(knots, s0); k < knots.length; k++) {
        if (knots[k] >= s1) break;
        if (knots[k] > s0) cuts.push(knots[k]);
      }
      cuts.push(s1);
      for (let k = 0; k + 1 < cuts.length; k++) {
        const [a, b] = [curve(cuts[k]), curve(cuts[k + 1])];
        pieces(cam, add(a.point, scale(a.side, offset)), add(b.point, scale(b.side, offset)), PIECE_LENGTH,
          (pa, pb, z) => queue(z, () => stroke(pa, pb, lineWidth, colour)));
      }
    }

    // The polyline `points` dashed, the pattern running on across its pieces.
    function queueDashed(cam, queue, points, lineWidth, colour, bias = 0) {
      let offset = 0;
      for (let k = 0; k + 1 < points.length; k++) {
        pieces(cam, points[k], points[k + 1], PIECE_LENGTH, (pa, pb, z) => {
          const at = offset;
          queue(z + bias, () => dashed(pa, pb, lineWidth, colour, at));
          offset += Math.hypot(pb.x - pa.x, pb.y - pa.y);
        });
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

    // The arm: capsules with outline and shine, the pen in its own colour; the joint origins
    // over the links that carry them; the TCP.
    function queueArm(cam, frame, queue) {
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
      frame.joints.slice(0, -1).forEach((p) => {
        const q = project(cam, p);
        if (q) queue(q.z - 0.08, () => disc(q, 4, JOINT_COLOUR, "#ffffff"));
      });
      const tcp = project(cam, frame.tcp);
      if (tcp) queue(tcp.z - 0.03, () => disc(tcp, 4.5, PEN_COLOUR, "#ffffff"));
    }

    // Tool cone: half-angle thetaMax around n, apex at the TCP, opening back along the pen.
    function queueCone(cam, queue, apex, n, thetaMax) {
      const u = perpendicular(n);
      const v = cross(n, u);
      const coneRadius = CONE_LENGTH * Math.tan((thetaMax * Math.PI) / 180);
      const base = sub(apex, scale(n, CONE_LENGTH));
      const rim = [];
      for (let k = 0; k <= 36; k++) {
        const phi = (2 * Math.PI * k) / 36;
        rim.push(add(base, add(scale(u, coneRadius * Math.cos(phi)), scale(v, coneRadius * Math.sin(phi)))));
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
    }

    // Tool axis through the TCP: along the pen and a little beyond the tip.
    function queueAxis(cam, queue, frame, colour) {
      pieces(cam, sub(frame.tcp, scale(frame.axis, 1.1 * CONE_LENGTH)), add(frame.tcp, scale(frame.axis, 0.45 * CONE_LENGTH)),
        0.03, (a, b, z) => queue(z - 0.04, () => stroke(a, b, 2, colour)));
    }

    function drawBackground() {
      const gradient = ctx.createLinearGradient(0, 0, 0, height);
      gradient.addColorStop(0, "#f9fbfd");
      gradient.addColorStop(1, "#dfe5ee");
      ctx.fillStyle = gradient;
      ctx.fillRect(0, 0, width, height);
    }

    // The timeline: `spans` ({from, to, colour}, in s) and the cursor at `current`.
    function drawTimeline(spans, current) {
      const w = timeline.clientWidth;
      const h = timeline.clientHeight;
      tctx.clearRect(0, 0, w, h);
      const x = (t) => (duration > 0 ? (t / duration) * w : 0);
      for (const span of spans) {
        tctx.fillStyle = span.colour;
        if (duration > 0) tctx.fillRect(x(span.from), 0, Math.max(1, x(span.to) - x(span.from)), h);
        else tctx.fillRect(0, 0, w, h);
      }
      tctx.fillStyle = "#1d2430";
      tctx.fillRect(Math.min(w - 2, Math.max(0, x(current) - 1)), 0, 2, h);
    }

    // -------------------------------------------------------------- read-out and legend
    const text = (id, value) => {
      document.getElementById(id).textContent = value;
    };
    // The legend: one swatch per [colour, label, dashed] entry.
    function buildLegend(entries) {
      const legend = document.getElementById("legend");
      for (const [colour, name, isDashed] of entries) {
        const item = document.createElement("span");
        const swatch = document.createElement("span");
        swatch.className = isDashed ? "swatch dashed" : "swatch";
        swatch.style.color = colour;
        if (!isDashed) swatch.style.background = colour;
        item.append(swatch, name);
        legend.append(item);
      }
    }
    // The legend's entries for the cell's solids.
    function cellLegend() {
      const entries = [];
      const surfaces = data.obstacles.filter((o) => o.surface);
      const others = data.obstacles.filter((o) => !o.surface);
      if (surfaces.length > 0) {
        entries.push([SURFACE_EDGE, (surfaces.length > 1 ? "work plates" : "work plate") + " (only the pen may touch)"]);
      }
      if (others.length > 0) entries.push([OBSTACLE_EDGE, "obstacles: " + others.map((o) => o.name).join(", ")]);
      return entries;
    }

    // -------------------------------------------------------------- playback
    // Starts the page: `page.along` ({p0, d}), or `page.back` (a unit vector), and
    // `page.target` (optional) for the view; `page.frame(frame, t)` adds the page's values to
    // an interpolated frame; `page.queue(cam, frame, queue)` queues its drawing;
    // `page.cone(frame)` gives the tool cone ({n, thetaMax}, or null for none);
    // `page.axisColour(frame)`; `page.spans` the timeline; `page.readout(frame, time)`;
    // `page.legend` and `page.summary`.
    function run(page) {
      // The view turns and zooms about the page's target (the bounds' centre unless it names
      // one), from far enough to hold the bounds.
      const middle = scale(add(bounds.lo, bounds.hi), 0.5);
      centre = page.target || middle;
      radius = Math.max(0.2, 0.5 * norm(sub(bounds.hi, bounds.lo)) + 0.25 * norm(sub(centre, middle)));
      along = page.along;
      back = page.back || null;
      resetView();

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

      function frameAt(t) {
        const frame = poseAt(t);
        if (page.frame) page.frame(frame, t);
        return frame;
      }
      function drawScene(cam, frame) {
        const items = [];
        const queue = (depth, draw) => items.push({ depth, draw });
        queueCell(cam, queue);
        page.queue(cam, frame, queue);
        queueArm(cam, frame, queue);
        const cone = page.cone(frame);
        if (cone) queueCone(cam, queue, frame.tcp, cone.n, cone.thetaMax);
        queueAxis(cam, queue, frame, page.axisColour(frame));
        items.sort((p, q) => q.depth - p.depth);
        ctx.lineCap = "round";
        for (const item of items) item.draw();
      }

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
        drawTimeline(page.spans, current);
        page.readout(frame, current);
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
      // Scrubbing redraws at once, so the scene and the read-out follow the bar without waiting
      // for the next animation frame.
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

      // ------------------------------------------------------------ start
      text("summary", page.summary);
      buildLegend(page.legend);
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
    }

    return {
      steps,
      last,
      duration,
      bounds,
      include,
      project,
      stroke,
      disc,
      label,
      pieces,
      queuePlane,
      queueCurve,
      queueDashed,
      text,
      cellLegend,
      run,
    };
  }

  return {
    LINK_COLOUR,
    PEN_COLOUR,
    LINE_COLOUR,
    CONE_EDGE,
    AXIS_COLOUR,
    AXIS_OUT_COLOUR,
    SURFACE_FILL,
    SURFACE_EDGE,
    PIECE_LENGTH,
    add,
    sub,
    scale,
    dot,
    cross,
    norm,
    unit,
    mix,
    mix3,
    lastAtOrBefore,
    alongPath,
    readData,
    viewer,
  };
})();
