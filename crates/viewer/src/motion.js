// The motion page: one planned motion along a line or a path, on the core (`emg`).
(function () {
  const { add, scale, cross, unit, mix } = emg;
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

  const data = emg.readData();
  const viewer = emg.viewer(data);
  const { steps, last, duration, project, stroke, disc, label } = viewer;
  const task = data.task;
  const thetaMax = data.constraints.theta_max_deg;
  const tolerance = data.constraints.line_tolerance_m;
  const lateralDir = unit(cross(task.n, task.d));
  // A path task's path, sampled; undefined for a line.
  const path = task.path;
  const knots = path ? path.s : [];
  // The point at progress (arc length) s and the unit direction across the task there.
  function alongTask(s) {
    if (!path) return { point: add(task.p0, scale(task.d, s)), side: lateralDir };
    return emg.alongPath(path, s);
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

  viewer.include(onLine(sMin - extension), 0);
  viewer.include(onLine(sEnd), 0);
  if (path) for (const p of path.points) viewer.include(p, 0);

  // The recorded values at the frame's time, interpolated.
  function frame(f) {
    const [a, b] = [f.a, f.b];
    f.s = mix(a.s, b.s, f.f);
    f.lateral = mix(a.lateral, b.lateral, f.f);
    f.angle = mix(a.tool_angle_deg, b.tool_angle_deg, f.f);
    f.rho = mix(a.rho, b.rho, f.f);
    f.controller = a.controller;
  }

  function queue(cam, f, push) {
    // The work surface (a half-space) around the line.
    if (data.constraints.work_surface) {
      const margin = extension + 0.1;
      viewer.queuePlane(cam, push, task.p0, task.d, lateralDir, [sMin - margin, sMax + margin], [-0.2, 0.2],
        emg.SURFACE_FILL, emg.SURFACE_EDGE, true);
    }

    // Task line or path: the planned range solid, the rest faint; the tolerance on each side;
    // the start marked.
    const lineSegment = (s0, s1, lineWidth, colour, offset = 0) =>
      viewer.queueCurve(cam, push, alongTask, knots, s0, s1, lineWidth, colour, offset);
    lineSegment(sMin - extension, sMin, 1.5, "rgba(31, 157, 85, 0.45)");
    lineSegment(sMin, sMax, 3, emg.LINE_COLOUR);
    lineSegment(sMax, sEnd, 1.5, "rgba(31, 157, 85, 0.45)");
    for (const sign of [-1, 1]) lineSegment(sMin, sMax, 1, "rgba(31, 157, 85, 0.35)", sign * tolerance);
    const start = project(cam, task.p0);
    if (start) {
      push(start.z - 0.01, () => {
        disc(start, 6, emg.LINE_COLOUR, "#ffffff");
        label(start, "p0", "#145c33");
      });
    }

    // Tolerance ring around the line (path) at the TCP's foot point.
    const { point: foot, side } = alongTask(f.s);
    const ring = [];
    for (let k = 0; k <= 32; k++) {
      const phi = (2 * Math.PI * k) / 32;
      ring.push(add(foot, add(scale(side, tolerance * Math.cos(phi)), scale(task.n, tolerance * Math.sin(phi)))));
    }
    for (let k = 0; k < 32; k++) {
      const a = project(cam, ring[k]);
      const b = project(cam, ring[k + 1]);
      if (a && b) push((a.z + b.z) / 2, () => stroke(a, b, 1.2, "rgba(31, 157, 85, 0.7)"));
    }

    // TCP trace so far, coloured by the controller that drove each step.
    const trace = steps.slice(0, f.index + 1).map((s) => s.joints[s.joints.length - 1]);
    trace.push(f.tcp);
    for (let k = 0; k + 1 < trace.length; k++) {
      const colour = CONTROLLER_COLOURS[steps[k].controller || "none"];
      const a = project(cam, trace[k]);
      const b = project(cam, trace[k + 1]);
      if (a && b) push((a.z + b.z) / 2 - 0.02, () => stroke(a, b, 4, colour));
    }
  }

  // One timeline span per run of steps driven by the same controller.
  const spans = [];
  if (duration > 0) {
    let from = 0;
    for (let k = 1; k <= last; k++) {
      const acting = steps[from].controller;
      if (k < last && steps[k].controller === acting) continue;
      spans.push({ from: steps[from].t, to: steps[k].t, colour: CONTROLLER_COLOURS[acting || "none"] });
      from = k;
    }
  } else {
    spans.push({ from: 0, to: 0, colour: CONTROLLER_COLOURS[steps[0].controller || "none"] });
  }

  function readout(f, current) {
    const text = viewer.text;
    text("r-time", current.toFixed(2) + " s of " + duration.toFixed(2) + " s");
    // Of the plan's length on a line, of the whole path on a path task.
    const total = path ? path.length_m : data.path_length_m;
    const percent = total > 0 ? " (" + Math.round((100 * f.s) / total) + " %)" : "";
    text("r-path", f.s.toFixed(3) + " m of " + total.toFixed(3) + " m" + percent);
    text("r-lateral", (1000 * f.lateral).toFixed(1) + " mm (limit " + (1000 * tolerance).toFixed(1) + " mm)");
    const angle = document.getElementById("r-angle");
    angle.textContent = f.angle.toFixed(1) + "\u00b0 (limit " + thetaMax.toFixed(1) + "\u00b0)";
    angle.classList.toggle("limit", f.angle >= 0.9 * thetaMax);
    text("r-rho", f.rho.toFixed(3));
    const acting = f.controller ? CONTROLLER_LABELS[f.controller] : CONTROLLER_LABELS.none;
    text("r-step", f.index + " of " + last + ", " + acting);
  }

  const legend = [];
  const present = new Set(steps.map((s) => s.controller || "none"));
  for (const key of ["classical", "learned", "search", "none"]) {
    if (present.has(key)) legend.push([CONTROLLER_COLOURS[key], CONTROLLER_LABELS[key]]);
  }
  legend.push(
    [emg.LINK_COLOUR, "links"],
    [emg.PEN_COLOUR, "pen / TCP"],
    [emg.LINE_COLOUR, path ? "task path and tolerance" : "task line (p0 + s\u00b7d) and tolerance"],
    [emg.CONE_EDGE, "tool cone (" + thetaMax + "\u00b0 about n)"],
    [emg.AXIS_COLOUR, "tool axis"],
  );
  if (data.constraints.work_surface) legend.push([emg.SURFACE_EDGE, "work surface (only the pen may touch it)"]);
  legend.push(...viewer.cellLegend());

  viewer.run({
    // Look across the line (perpendicular to d), from the side of the task.
    along: { p0: task.p0, d: task.d },
    frame,
    queue,
    cone: () => ({ n: task.n, thetaMax }),
    axisColour: (f) => (f.angle > thetaMax ? emg.AXIS_OUT_COLOUR : emg.AXIS_COLOUR),
    spans,
    readout,
    legend,
    summary:
      data.robot + " \u00b7 " + last + " steps, " + duration.toFixed(2) + " s \u00b7 path length " +
      data.path_length_m.toFixed(3) + " m \u00b7 ended: " + data.termination,
  });
})();
