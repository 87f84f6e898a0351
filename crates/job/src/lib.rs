//! Jobs: a drawing or a set of seams planned as one program a robot runs. [`plan_job`]
//! ([`pipeline`]) is the list of its stages, each a function from one stage's result to the
//! next's:
//!
//! | stage | module | from → to |
//! |---|---|---|
//! | read | [`spec`] | a job file or a drawing's strokes → [`Job`] |
//! | order | [`order`] | [`Job`] → [`Ordering`]: strokes that meet end to end merged ([`order::merge`]), the order and directions that shorten the pen-up travel |
//! | plan strokes | [`plan_strokes`], [`stroke`] | [`Ordering`] → `Vec<`[`PlannedStroke`]`>`: each stroke to the limit by the search, resumed after a reconfiguration where one motion cannot finish it |
//! | connect | [`connect`] | `Vec<PlannedStroke>` → `Connected`: each part timed, lifted, and joined to the last by a free pen-up move that keeps clear of the part |
//! | reorder | [`reorder`] | `Connected` → `Option<Connected>`: where the order stage chose the order, runs of strokes moved to lower the estimated pen-up time, connected again |
//! | choose branches | [`branch`] | `Connected` → `Connected`: where the arm changes branch between strokes, one plan per stroke by the least pen-up time of the whole job; in both orders, the quicker program kept |
//! | write | [`write`] | `Connected` → [`JobFile`]: the `emg-job/3` file, every segment with its time span and motion ([`program`]) |
//!
//! Below the stages: [`measures`] (the lengths they share), [`free_space`] (the part and the
//! pen-up clearance), [`claims`] and [`shortfall`] (what a part draws, why a stretch is not);
//! beside them: [`verify_job`] re-checks a written program with the independent checker, and
//! [`place_job`] runs [`plan_job`] at the best places for the part.

mod abb_configuration;
pub mod branch;
pub mod claims;
pub mod connect;
mod controller_targets;
pub mod demo_jobs;
pub mod free_space;
mod industrial;
pub mod krl_program;
mod kuka_configuration;
pub mod measures;
pub mod motion;
pub mod order;
pub mod page;
pub mod pipeline;
pub mod place;
pub mod plan_error;
pub mod plan_strokes;
pub mod program;
pub mod rapid_program;
mod reach;
pub mod reorder;
pub mod setting;
pub mod setup;
pub mod shortfall;
pub mod spec;
pub mod stroke;
pub mod tolerance;
pub mod tool_output;
pub mod ur_program;
pub mod verify;
pub mod watch;
mod wrist;
pub mod write;

pub use abb_configuration::AbbConfiguration;
pub use branch::{BRANCH_CHANGE_RAD, BranchChoice, Branches, MAX_CARRIED_STROKES, choose_branches};
pub use claims::{COVERAGE_SLACK_M, Coverage, OnStroke, Stretch, part_coverage};
pub use connect::{
    BLEND_SHARE, CLEARANCE_LIFT_M, HOP_BLEND_SHARE, HOP_RISE, MAX_HELD_UP_DEPTH,
    MAX_HOP_RISE_LIFTS, ROLL_FROM_HOME_RAD,
};
pub use demo_jobs::valley_seams;
pub use free_space::{
    FreeSpace, LIFT_CONE_RUN, MAX_POINT_TRAVEL_M, PART, PEN_UP_CLEARANCE_SHARE, job_part,
    part_surfaces, with_part,
};
pub use industrial::MIN_TARGET_SPACING_M;
pub use kuka_configuration::KukaConfiguration;
pub use measures::{JOB_TOLERANCE_M, SAME_LENGTH_M};
pub use motion::Motion;
pub use order::merge::{Chain, merge_strokes};
pub use order::{Ordering, Oriented, merge_and_order, order_strokes, order_strokes_counted};
pub use page::{placement_map, viewer_page};
pub use pipeline::plan_job;
pub use place::{
    Certified, Moving, Place, PlaceError, PlaceFrame, PlaceSettings, Placement, Region, RegionEdge,
    SAME_SCORE, Score, Scored, place_job, place_score,
};
pub use plan_error::JobPlanError;
pub use plan_strokes::{CLOSED_STARTS, NEAR_HOME_BANDS_RAD, PlannedStroke};
pub use program::{
    JOB_FILE_FORMAT, JobFile, JobFileError, JobSummary, MAX_PROGRAM_S, Program, Segment,
    SegmentKind, StrokeReport,
};
pub use reach::{WristReach, default_placement};
pub use reorder::{MIN_SAVED_S, in_order, reorder_by_move_time};
pub use setting::InvalidSetting;
pub use setup::{JobPlanner, job_config, job_timing};
pub use shortfall::{LeftOut, Shortfall, Stop};
pub use spec::{JOB_FORMAT_VERSION, Job, JobError, JobSettings, JobSpec, Order, Tool, Transform};
pub use stroke::{StrokePart, StrokePlan, finish_from_the_end, plan_stroke, reachable_start_s};
pub use tolerance::DrawingTolerance;
pub use tool_output::{OutputBank, ToolOutput};
pub use verify::{JobCheck, JobCheckError, verify_job};
pub use watch::{Stopped, StopsWith, Unwatched, Watch};
