//! `cargo xtask gap-eval`: the lines whose bound is likely loose (`emg plan`'s continuity test,
//! `emg_planner::BoundNote::likely_loose`), asked from the far side
//! (`emg_planner::gap_probes`): motions planned back from points between the plan's end and
//! the bound, where each gets back to, and whether the arm can change from the plan's branch to
//! theirs in place or going back and forth along the line (`docs/results/gaps.{json,md}`).

use std::path::Path;

use emg_control::{Task, Tracking};
use emg_planner::{GapProbe, GapProbeOutcome, InPlaceConfig, Planner, gap_probes};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::precision_eval::Setting;
use crate::results::{SummaryPlace, shipped_results};
use crate::task_set_options::TaskSetOptions;
use crate::{progress, workspace};

/// The markers around the table of [`report_table`] in `docs/results/summary.md` (written there
/// by `cargo xtask report`, [`crate::workspace::RESULTS_SUMMARY`]).
const README_START: &str = "<!-- gaps:start -->";
/// See [`README_START`].
const README_END: &str = "<!-- gaps:end -->";

/// Where the table of likely-loose bounds ([`report_table`]) is shown: the results summary.
pub const SUMMARY: SummaryPlace = SummaryPlace::in_results_summary(
    README_START,
    README_END,
    "## Lines whose bound is likely loose\n\nThe lines of the precision table's corrected \
         step at 0.5 mm whose bound no chain of valid configurations joins to `p0`, asked from \
         the far side: motions planned back from beyond the plan's end, and motions in place \
         and along the line between their branches and the plan's (`cargo xtask gap-eval`; \
         `docs/results/gaps.md` per arm):\n\n",
);

/// Options of `gap-eval`.
#[derive(clap::Args)]
#[command(
    mut_arg("out_dir", |arg| arg.help("Output directory of gaps.{json,md}")),
)]
pub struct Args {
    /// Lines: the first this many tasks of the task set (`precision-eval`'s).
    #[arg(long, default_value_t = 400)]
    tasks: usize,
    /// The line tolerance (mm).
    #[arg(long, default_value_t = 0.5)]
    tolerance_mm: f64,
    /// Random configurations each motion in place, and each motion along the line, may draw
    /// (its budget).
    #[arg(long, default_value_t = InPlaceConfig::default().samples)]
    samples: usize,
    /// Worker threads, task set, robot file and output directory.
    #[command(flatten)]
    common: TaskSetOptions,
}

/// A line whose bound is likely loose, and its probes.
#[derive(Serialize, Deserialize)]
pub struct LooseLine {
    /// Index in the task set.
    pub task: usize,
    /// The plan's length (m).
    pub planned_m: f64,
    /// The bound (m).
    pub bound_m: f64,
    /// The motions planned back from beyond the plan's end.
    pub probes: Vec<GapProbe>,
}

impl LooseLine {
    /// The longest motion from `p0` shown: the plan, or a motion back that passes `p0`.
    pub fn longest_shown_m(&self) -> f64 {
        self.probes
            .iter()
            .filter(|probe| probe.outcome == GapProbeOutcome::PassesP0)
            .map(|probe| probe.from_m)
            .fold(self.planned_m, f64::max)
    }

    /// The longest motion from `p0` shown with one stop to reconfigure in place: the plan to
    /// where a motion back is joined to it in place, then that motion read forwards to where
    /// it started; at least [`LooseLine::longest_shown_m`].
    pub fn longest_with_one_stop_m(&self) -> f64 {
        self.probes
            .iter()
            .filter(|probe| {
                matches!(
                    probe.outcome,
                    GapProbeOutcome::Overlaps {
                        joined_in_place: Some(true),
                        ..
                    }
                )
            })
            .map(|probe| probe.from_m)
            .fold(self.longest_shown_m(), f64::max)
    }

    /// The longest motion from `p0` shown going back and forth along the line: the plan joined
    /// along the line to a motion back ([`GapProbe::joined_along_line`]), then that motion read
    /// forwards to where it started; at least [`LooseLine::longest_with_one_stop_m`].
    pub fn longest_back_and_forth_m(&self) -> f64 {
        self.probes
            .iter()
            .filter(|probe| probe.joined_along_line == Some(true))
            .map(|probe| probe.from_m)
            .fold(self.longest_with_one_stop_m(), f64::max)
    }
}

/// The whole record written to `gaps.json`.
#[derive(Serialize, Deserialize)]
pub struct Record {
    /// Robot name.
    pub robot: String,
    /// The command that wrote the record.
    pub command: String,
    /// Task set.
    pub tasks: String,
    /// Lines planned (the first of the set).
    pub line_count: usize,
    /// The line tolerance (mm).
    pub tolerance_mm: f64,
    /// The settings of the motions in place and along the line.
    pub in_place: InPlaceConfig,
    /// Σ plan and Σ bound over every line (m).
    pub planned_m: f64,
    /// See `planned_m`.
    pub bound_m: f64,
    /// The lines whose bound is likely loose, in task order.
    pub loose: Vec<LooseLine>,
    /// Machine and worker threads.
    pub machine: String,
    /// See `machine`.
    pub threads: usize,
}

/// Plans every line, probes those whose bound is likely loose, writes the record and its table.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let workspace::PlannerSetup { planner, tasks, .. } =
        args.common.planner_setup(args.tasks, "gap-eval")?;
    let setting = Setting {
        tolerance_mm: args.tolerance_mm,
        tracking: Tracking::Corrected,
        learned: true,
    };
    let planner = planner.with_config(setting.config())?;
    let in_place = InPlaceConfig {
        samples: args.samples,
        ..InPlaceConfig::default()
    };
    in_place.validate()?;
    let pool = workspace::thread_pool(args.common.threads)?;
    let bar = progress::bar(tasks.len() as u64, "lines");
    let lines: Vec<(f64, f64, Option<LooseLine>)> = pool.install(|| {
        tasks
            .par_iter()
            .enumerate()
            .map(|(index, task)| {
                let line = probe_line(&planner, &setting, &in_place, index, task);
                bar.inc(1);
                line
            })
            .collect::<anyhow::Result<_>>()
    })?;
    bar.finish();
    let record = Record {
        robot: planner.robot().name().to_string(),
        command: workspace::command_for("gap-eval", &args.common.robot),
        tasks: workspace::relative(&args.common.task_file),
        line_count: tasks.len(),
        tolerance_mm: args.tolerance_mm,
        in_place,
        planned_m: lines.iter().map(|(planned, _, _)| planned).sum(),
        bound_m: lines.iter().map(|(_, bound, _)| bound).sum(),
        loose: lines
            .into_iter()
            .filter_map(|(_, _, loose)| loose)
            .collect(),
        machine: workspace::machine(),
        threads: pool.current_num_threads(),
    };
    workspace::write_results(&args.common.out_dir, "gaps", &record, &markdown(&record))
}

/// The plan's length and bound of one line, with its probes when its bound is likely loose.
fn probe_line(
    planner: &Planner,
    setting: &Setting,
    in_place: &InPlaceConfig,
    index: usize,
    task: &Task,
) -> anyhow::Result<(f64, f64, Option<LooseLine>)> {
    let plan = planner.plan(task, &setting.request())?;
    let note = planner.bound_note(task, &plan);
    let planned_m = plan.trajectory.path_length_m;
    let loose = note.likely_loose.then(|| LooseLine {
        task: index,
        planned_m,
        bound_m: note.reachable_m,
        probes: gap_probes(planner, task, &plan, in_place),
    });
    Ok((planned_m, note.reachable_m, loose))
}

/// What one probe found, in words for the table.
fn outcome_words(probe: &GapProbe) -> String {
    let along = match probe.joined_along_line {
        Some(true) => "; joined along the line",
        Some(false) => "; not joined along the line",
        None => "",
    };
    let outcome = match &probe.outcome {
        GapProbeOutcome::NoStart => "no motion starts there".into(),
        GapProbeOutcome::PassesP0 => "passes p0: a longer motion".into(),
        GapProbeOutcome::StopsShort => "stops before the plan's end".into(),
        GapProbeOutcome::Overlaps {
            at_m,
            joined_in_place,
            joint_gap_rad,
        } => match (joined_in_place, joint_gap_rad) {
            (Some(joined), Some(gap)) => format!(
                "overlaps; at {at_m:.3} m {} in place ({gap:.2} rad apart)",
                if *joined { "joined" } else { "not joined" }
            ),
            _ => format!("overlaps; at {at_m:.3} m not compared (not a valid configuration)"),
        },
    };
    outcome + along
}

/// What a record's probes add up to.
struct Summary {
    /// Σ plan and Σ bound over the lines whose bound is likely loose (m).
    loose_planned_m: f64,
    /// See `loose_planned_m`.
    loose_bound_m: f64,
    /// Σ of their longest motions from `p0` shown: without a stop, with one stop in place, and
    /// going back and forth along the line (m).
    shown_m: f64,
    /// See `shown_m`.
    shown_with_stop_m: f64,
    /// See `shown_m`.
    shown_back_and_forth_m: f64,
    /// Motions planned back, and of them: passing `p0`, joined in place, not joined, not
    /// compared, stopping before the plan's end, without a start.
    probes: usize,
    /// See `probes`.
    passes_p0: usize,
    /// See `probes`.
    joined: usize,
    /// See `probes`.
    not_joined: usize,
    /// See `probes`.
    not_compared: usize,
    /// See `probes`.
    stops_short: usize,
    /// See `probes`.
    no_start: usize,
    /// Motions back that do not pass `p0` (with a start), and of them those joined to the plan
    /// along the line.
    asked_along_line: usize,
    /// See `asked_along_line`.
    joined_along_line: usize,
    /// Σ plan / Σ bound over all lines, and over the lines whose bound is not likely loose.
    share: f64,
    /// See `share`.
    share_of_others: f64,
}

impl Summary {
    fn of(record: &Record) -> Self {
        let loose = &record.loose;
        let probes: Vec<&GapProbe> = loose.iter().flat_map(|line| &line.probes).collect();
        let count = |wanted: &dyn Fn(&GapProbe) -> bool| {
            probes.iter().filter(|probe| wanted(probe)).count()
        };
        let outcome_is = |wanted: GapProbeOutcome| move |probe: &GapProbe| probe.outcome == wanted;
        let joined = |wanted: Option<bool>| {
            move |probe: &GapProbe| match probe.outcome {
                GapProbeOutcome::Overlaps {
                    joined_in_place, ..
                } => joined_in_place == wanted,
                _ => false,
            }
        };
        // Sums from +0, not the empty sum's −0, which prints as "-0.00" when no line is loose.
        let total = |of: fn(&LooseLine) -> f64| loose.iter().map(of).fold(0.0, |a, b| a + b);
        let loose_planned_m = total(|line| line.planned_m);
        let loose_bound_m = total(|line| line.bound_m);
        Self {
            loose_planned_m,
            loose_bound_m,
            shown_m: total(LooseLine::longest_shown_m),
            shown_with_stop_m: total(LooseLine::longest_with_one_stop_m),
            shown_back_and_forth_m: total(LooseLine::longest_back_and_forth_m),
            probes: probes.len(),
            passes_p0: count(&outcome_is(GapProbeOutcome::PassesP0)),
            joined: count(&joined(Some(true))),
            not_joined: count(&joined(Some(false))),
            not_compared: count(&joined(None)),
            stops_short: count(&outcome_is(GapProbeOutcome::StopsShort)),
            no_start: count(&outcome_is(GapProbeOutcome::NoStart)),
            asked_along_line: count(&|probe| probe.joined_along_line.is_some()),
            joined_along_line: count(&|probe| probe.joined_along_line == Some(true)),
            share: record.planned_m / record.bound_m,
            share_of_others: (record.planned_m - loose_planned_m)
                / (record.bound_m - loose_bound_m),
        }
    }
}

/// The report's table: one row per shipped arm with a `gaps.json`.
pub fn report_table(results: &Path) -> anyhow::Result<String> {
    let mut md = String::from(
        "| arm | tolerance | lines: Σ plan / Σ bound | likely loose | their Σ plan / Σ bound (m) \
         | longest shown from `p0` (m) | with one stop in place (m) | back and forth along the \
         line (m) | motions back: past `p0` / joined in place / not joined / stop short / no start \
         | joined along the line | Σ plan / Σ bound over the others |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (shipped, record) in shipped_results::<Record>(results, "gaps.json")? {
        let summary = Summary::of(&record);
        md.push_str(&format!(
            "| {} | {} mm | {:.3} | {} of {} | {:.2} / {:.2} | {:.2} | {:.2} | {:.2} | {} / {} / {} / \
             {} / {} | {} of {} | {:.3} |\n",
            shipped.name,
            record.tolerance_mm,
            summary.share,
            record.loose.len(),
            record.line_count,
            summary.loose_planned_m,
            summary.loose_bound_m,
            summary.shown_m,
            summary.shown_with_stop_m,
            summary.shown_back_and_forth_m,
            summary.passes_p0,
            summary.joined,
            summary.not_joined,
            summary.stops_short,
            summary.no_start,
            summary.joined_along_line,
            summary.asked_along_line,
            summary.share_of_others,
        ));
    }
    Ok(md)
}

fn markdown(record: &Record) -> String {
    let summary = Summary::of(record);
    let mut md = format!(
        "# Lines whose bound is likely loose, asked from the far side ({})\n\n\
         Generated by `{}` on {} ({} threads). The first {} tasks of `{}` planned as \
         `precision-eval`'s corrected step at {} mm plans them (`emg plan`'s default search, \
         no work surface, 30° cone); Σ plan / Σ bound over all of them: {:.3}. On {} of them the \
         plan ends below 0.9 of its bound and the bound's continuity test finds no chain of \
         valid configurations joining `p0` to 95 % of it (`emg plan`'s note \"the bound is \
         likely loose here\"): {:.2} m planned of their Σ {:.2} m bound. Each is asked from the \
         far side (`emg_planner::gap_probes`): the same planner, its far-end stage left out, \
         plans the line backwards from 3 and 10 grid steps past the plan's end, from halfway to \
         the bound and from half a grid step before it (the motions the search's own far-end \
         stage asks for from the same points, so none should pass `p0`), and where a motion \
         back passes the plan's end without reaching `p0`, \
         a motion in place (`emg_planner::in_place_motion`, RRT-Connect on the configurations \
         that hold the TCP on one point, {} draws, seed {}) tries to join the plan's \
         configuration there to the motion back's. Where a motion back does not pass `p0`, a \
         motion along the line (`emg_planner::motion_along_line`, the same search on the \
         configurations that hold the TCP anywhere on the line up to where the motion back \
         starts, going back and forth as it needs) tries to join the plan's configurations to \
         the motion back's.\n\n\
         From {} points beyond the plans' ends, the motions planned back: {} pass `p0` (read \
         forwards, a motion from `p0` longer than the plan: the search missed it), {} pass the \
         plan's end and are joined to it in place, {} pass it and are not, {} pass it where a \
         configuration could not be compared, {} stop before the plan's end, and from {} no \
         motion starts. The longest motion from `p0` shown on these lines (the plan or a motion back past `p0`) sums to {:.2} m of \
         their {:.2} m bound, {:.2} m with one stop to reconfigure in place (the plan to where \
         a motion back is joined to it, then that motion), {:.2} m going back and forth along \
         the line ({} of the {} motions back that do not pass `p0` are joined to the plan along \
         it: the plan, back along the line while the arm changes over, then that motion). A \
         motion back joined to the plan by neither is what the continuity test suspected: the \
         bound's configurations there lie on branches no motion from `p0` that was found \
         reaches, even one that retraces the line. Σ plan / Σ bound over the other lines: \
         {:.3}.\n\n",
        record.robot,
        record.command,
        record.machine,
        record.threads,
        record.line_count,
        record.tasks,
        record.tolerance_mm,
        summary.share,
        record.loose.len(),
        summary.loose_planned_m,
        summary.loose_bound_m,
        record.in_place.samples,
        record.in_place.seed,
        summary.probes,
        summary.passes_p0,
        summary.joined,
        summary.not_joined,
        summary.not_compared,
        summary.stops_short,
        summary.no_start,
        summary.shown_m,
        summary.loose_bound_m,
        summary.shown_with_stop_m,
        summary.shown_back_and_forth_m,
        summary.joined_along_line,
        summary.asked_along_line,
        summary.share_of_others,
    );
    md.push_str("| task | plan (m) | bound (m) | from (m) | back to (m) | what it shows |\n");
    md.push_str("|---|---|---|---|---|---|\n");
    for line in &record.loose {
        for (i, probe) in line.probes.iter().enumerate() {
            let (task, planned, bound) = if i == 0 {
                (
                    line.task.to_string(),
                    format!("{:.3}", line.planned_m),
                    format!("{:.3}", line.bound_m),
                )
            } else {
                Default::default()
            };
            md.push_str(&format!(
                "| {task} | {planned} | {bound} | {:.3} | {:.3} | {} |\n",
                probe.from_m,
                probe.back_to_m,
                outcome_words(probe)
            ));
        }
    }
    md
}
