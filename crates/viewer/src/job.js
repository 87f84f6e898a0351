// The job page: a whole program (strokes, and the moves between them) on the core (`emg`).
(function () {
  const { mix, unit, lastAtOrBefore } = emg;
  // A stroke's stretches not drawn, faint; the ink laid so far; the pen-up moves, dashed; the
  // timeline's lifts (retreat, approach).
  const UNREACHED_COLOUR = "rgba(179, 38, 30, 0.40)";
  const INK_COLOUR = "#123c69";
  const MOVE_COLOUR = "#2b6cb0";
  const LIFT_COLOUR = "#9ec5e8";
  const KIND_COLOURS = { stroke: emg.LINE_COLOUR, retreat: LIFT_COLOUR, approach: LIFT_COLOUR, travel: MOVE_COLOUR };

  const data = emg.readData();
  const viewer = emg.viewer(data);
  const { steps, last, duration, project, stroke, disc, label } = viewer;
  const thetaMax = data.constraints.theta_max_deg;
  const tolerance = data.constraints.line_tolerance_m;
  const segments = data.segments;
  const starts = segments.map((segment) => segment.start_s);
  const strokes = data.strokes;

  // The segment under way at time t (at a boundary, the one that starts there).
  const segmentAt = (t) => lastAtOrBefore(starts, t);

  // Pieces of the TCP's trace between steps k and k + 1 that lay ink: both pen down, within a
  // stroke part.
  const ink = steps.slice(0, last).map((a, k) => {
    const b = steps[k + 1];
    const segment = segments[segmentAt((a.t + b.t) / 2)];
    return a.s !== undefined && b.s !== undefined && segment !== undefined && segment.kind === "stroke";
  });

  // Bounds: every stroke and every move's TCP; the view looks across the work from beyond it.
  let centroid = [0, 0, 0];
  let count = 0;
  for (const s of strokes) {
    for (const p of s.path.points) {
      viewer.include(p, 0);
      centroid = emg.add(centroid, p);
      count += 1;
    }
  }
  for (const segment of segments) for (const p of segment.tcp || []) viewer.include(p, 0);
  centroid = emg.scale(centroid, 1 / Math.max(1, count));
  // The strokes' mean surface normal (the pen points along it; the surface faces against it).
  const normal = unit(strokes.reduce((sum, s) => emg.add(sum, s.normal), [0, 0, 0]));
  const outward = unit([centroid[0], centroid[1], 0]);
  const back = unit(emg.add(emg.scale(normal, -0.8), emg.add([-outward[1], outward[0], 0], emg.scale(outward, 0.3))));

  function frame(f, t) {
    f.segmentIndex = segments.length > 0 ? segmentAt(t) : -1;
    f.segment = segments[f.segmentIndex];
    const [a, b] = [f.a, f.b];
    f.penDown = f.segment !== undefined && f.segment.kind === "stroke" && a.s !== undefined && b.s !== undefined;
    if (f.penDown) {
      f.s = mix(a.s, b.s, f.f);
      f.lateral = mix(a.lateral, b.lateral, f.f);
      f.angle = mix(a.tool_angle_deg, b.tool_angle_deg, f.f);
    }
  }

  function queue(cam, f, push) {
    // Every stroke: its stretches drawn solid, the rest faint; its start numbered.
    for (const s of strokes) {
      const curve = (at) => emg.alongPath(s.path, at);
      for (const [from, to] of s.reached) viewer.queueCurve(cam, push, curve, s.path.s, from, to, 3, emg.LINE_COLOUR);
      for (const [from, to] of s.unreached) viewer.queueCurve(cam, push, curve, s.path.s, from, to, 2, UNREACHED_COLOUR);
      const start = project(cam, s.path.points[0]);
      if (start) {
        push(start.z - 0.01, () => {
          disc(start, 3.5, emg.LINE_COLOUR, "#ffffff");
          label(start, String(s.stroke), "#145c33");
        });
      }
    }

    // The TCP's pen-up moves, dashed; the one under way bolder.
    segments.forEach((segment, k) => {
      if (!segment.tcp) return;
      const current = k === f.segmentIndex;
      viewer.queueDashed(cam, push, segment.tcp, current ? 3 : 1.8, MOVE_COLOUR, -0.015);
    });

    // The ink laid so far: the TCP's trace pen down.
    const tcpOf = (step) => step.joints[step.joints.length - 1];
    const inked = (a, b) => {
      const pa = project(cam, a);
      const pb = project(cam, b);
      if (pa && pb) push((pa.z + pb.z) / 2 - 0.02, () => stroke(pa, pb, 4.5, INK_COLOUR));
    };
    for (let k = 0; k < f.index; k++) if (ink[k]) inked(tcpOf(steps[k]), tcpOf(steps[k + 1]));
    if (f.index < last && ink[f.index]) inked(tcpOf(steps[f.index]), f.tcp);
  }

  // The timeline: one span per segment, coloured by its kind.
  const spans = segments.map((segment) => ({
    from: segment.start_s,
    to: segment.end_s,
    colour: KIND_COLOURS[segment.kind] || "#9aa3af",
  }));

  function readout(f, current) {
    const text = viewer.text;
    text("r-time", current.toFixed(2) + " s of " + duration.toFixed(2) + " s");
    text("r-segment", f.segment ? f.segment.name + " (" + (f.segmentIndex + 1) + " of " + segments.length + ")" : "none");
    const angle = document.getElementById("r-angle");
    if (f.penDown) {
      const total = strokes[f.segment.stroke].path.length_m;
      const percent = total > 0 ? " (" + Math.round((100 * f.s) / total) + " %)" : "";
      text("r-stroke", f.s.toFixed(3) + " m of " + total.toFixed(3) + " m" + percent);
      text("r-lateral", (1000 * f.lateral).toFixed(2) + " mm (limit " + (1000 * tolerance).toFixed(2) + " mm)");
      angle.textContent = f.angle.toFixed(1) + "\u00b0 (limit " + thetaMax.toFixed(1) + "\u00b0)";
      angle.classList.toggle("limit", f.angle >= 0.9 * thetaMax);
    } else {
      text("r-stroke", "pen up");
      text("r-lateral", "\u2014");
      angle.textContent = "free (pen up)";
      angle.classList.remove("limit");
    }
    text("r-step", f.index + " of " + last);
  }

  const legend = [
    [emg.LINE_COLOUR, "strokes: stretches drawn"],
  ];
  if (strokes.some((s) => s.unreached.length > 0)) legend.push([UNREACHED_COLOUR, "stretches not drawn"]);
  legend.push(
    [INK_COLOUR, "ink laid so far"],
    [MOVE_COLOUR, "pen-up moves (retreat, travel, approach) of the TCP", true],
    [LIFT_COLOUR, "retreat / approach (timeline)"],
    [emg.LINK_COLOUR, "links"],
    [emg.PEN_COLOUR, "pen / TCP"],
    [emg.CONE_EDGE, "tool cone (" + thetaMax + "\u00b0 about n, pen down)"],
    [emg.AXIS_COLOUR, "tool axis"],
    ...viewer.cellLegend(),
  );

  const strokeCount = strokes.length === 1 ? "1 stroke" : strokes.length + " strokes";
  viewer.run({
    along: { p0: centroid, d: unit([-centroid[1], centroid[0], 0]) },
    // The view turns and zooms about the work, and looks at the face of its surface from the
    // side of the arm's reach towards it, where the arm hides the least of it.
    target: centroid,
    back,
    frame,
    queue,
    cone: (f) => (f.penDown ? { n: f.segment.n, thetaMax } : null),
    axisColour: (f) => (f.penDown && f.angle > thetaMax ? emg.AXIS_OUT_COLOUR : emg.AXIS_COLOUR),
    spans,
    readout,
    legend,
    summary:
      data.robot + " \u00b7 " + strokeCount + ", " + data.drawn_m.toFixed(3) + " m of " + data.length_m.toFixed(3) +
      " m drawn \u00b7 " + segments.length + " segments, " + duration.toFixed(2) + " s",
  });
})();
