//! Motions that hold the TCP on the line: in place on one point, or back and forth along a
//! stretch of it, every constraint held on the way.
//!
//! Two motions along a line may cover the same point on different self-motion branches: one
//! from `p0` that ends there, another that goes on from there to the end of the bound. They join
//! into one motion only if the arm can change from one branch to the other somewhere, and where
//! it cannot do so on the move it could still stop and reconfigure with the TCP held still
//! (the tool axis free inside its cone), or go back along the line it has drawn while it
//! changes over. The configurations that put the TCP on a point form a manifold (of dimension
//! `dof − 3`), those that put it on a stretch of the line one of dimension `dof − 2`;
//! [`in_place_motion`] and [`motion_along_line`] search them with a bidirectional
//! rapidly-exploring random tree (RRT-Connect): random configurations projected onto the point
//! (or the nearest point of the stretch; [`emg_kinematics::project_to_point`]), trees grown
//! toward them in short joint steps, each step's end and midpoint projected and held to every
//! constraint ([`emg_control::first_violation`]). A motion found is a witness that the
//! configurations join; none found within the budget is evidence, not proof, that they do not.

use emg_control::{ConstraintConfig, OutOfRange, Task, first_violation};
use emg_kinematics::{JointVector, POINT_TOLERANCE_M, Robot, Vec3, project_to_point};
use kdtree::KdTree;
use kdtree::distance::squared_euclidean;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Settings of [`in_place_motion`] and [`motion_along_line`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InPlaceConfig {
    /// Random configurations drawn (the budget: it counts draws, not time).
    pub samples: usize,
    /// Longest joint step of a tree's edge (rad, Euclidean over the joints).
    pub step_rad: f64,
    /// Seed of the random draws.
    pub seed: u64,
}

impl Default for InPlaceConfig {
    fn default() -> Self {
        Self {
            samples: 20_000,
            step_rad: 0.1,
            seed: 20_261_128,
        }
    }
}

impl InPlaceConfig {
    /// Checks every value against its allowed range.
    pub fn validate(&self) -> Result<(), OutOfRange> {
        OutOfRange::require(
            "in_place.samples",
            self.samples as f64,
            "[1, 1000000]",
            |n| (1.0..=1e6).contains(&n),
        )?;
        OutOfRange::require("in_place.step_rad", self.step_rad, "[0.001, 1]", |s| {
            (1e-3..=1.0).contains(&s)
        })
    }
}

/// Steps a tree grows toward one draw before the next draw.
const STEPS_PER_DRAW: usize = 50;

/// Steps the other tree grows toward a newly reached node to meet it.
const STEPS_PER_CONNECT: usize = 100;

/// Joint distance (rad) at which two trees' nodes are the same configuration: a step toward a
/// configuration on the manifold within `step_rad` lands on it.
const MET_RAD: f64 = 1e-9;

/// A motion from `from` to `to` (both with the TCP within
/// [`POINT_TOLERANCE_M`] of `point`, as [`project_to_point`] puts them) along
/// which the TCP stays on `point` and every configuration holds `constraints` on `task`, each
/// configuration within twice `config.step_rad` (Euclidean) of the one before; `None` where the
/// search finds none within its budget, or where `from` or `to` is not a valid configuration on
/// the point (module documentation). Deterministic for a given `config.seed`.
pub fn in_place_motion(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    point: &Vec3,
    from: &JointVector,
    to: &JointVector,
    config: &InPlaceConfig,
) -> Option<Vec<JointVector>> {
    let manifold = Manifold {
        robot,
        task,
        constraints,
        hold: Hold::Point(*point),
        step_rad: config.step_rad,
    };
    for end in [from, to] {
        let on_point = (robot.forward(end).tcp() - point).norm() <= POINT_TOLERANCE_M;
        if !on_point || !manifold.valid(end) {
            return None;
        }
    }
    connect(&manifold, &[*from], &[*to], config)
}

/// A motion from one of `from` to one of `to` along which the TCP stays on `task`'s line
/// between `from_m` and `to_m` along it (going back and forth as it needs) and every
/// configuration holds `constraints`, each within twice `config.step_rad` (Euclidean) of the
/// one before; every configuration but the first and last has its TCP within
/// [`POINT_TOLERANCE_M`] of the line. `from` and `to` are each configurations already joined to
/// one another (a motion's, say): the trees grow from all of them. Those that break a
/// constraint or whose TCP is not on the stretch (within the line tolerance) are left out;
/// `None` where none is left on a side, on a path task, or where the search finds no motion
/// within its budget (module documentation). Deterministic for a given `config.seed`.
#[allow(clippy::too_many_arguments)]
pub fn motion_along_line(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    from_m: f64,
    to_m: f64,
    from: &[JointVector],
    to: &[JointVector],
    config: &InPlaceConfig,
) -> Option<Vec<JointVector>> {
    // False as well where either end is not a number.
    let ordered = from_m <= to_m;
    if task.path.is_some() || !ordered {
        return None;
    }
    let manifold = Manifold {
        robot,
        task,
        constraints,
        hold: Hold::Stretch { from_m, to_m },
        step_rad: config.step_rad,
    };
    let tolerance = constraints.line_tolerance_m;
    let on_stretch = |q: &&JointVector| {
        let along = task.progress(&robot.forward(q).tcp());
        (from_m - tolerance..=to_m + tolerance).contains(&along) && manifold.valid(q)
    };
    let [from, to] =
        [from, to].map(|ends| ends.iter().filter(on_stretch).copied().collect::<Vec<_>>());
    if from.is_empty() || to.is_empty() {
        return None;
    }
    connect(&manifold, &from, &to, config)
}

/// RRT-Connect on `manifold` between trees rooted at every one of `from` and of `to`: the
/// motion from a root of `from` to a root of `to`, `None` where none is found within
/// `config.samples` draws.
fn connect(
    manifold: &Manifold,
    from: &[JointVector],
    to: &[JointVector],
    config: &InPlaceConfig,
) -> Option<Vec<JointVector>> {
    for start in from {
        for end in to {
            if (start - end).norm() <= manifold.step_rad
                && manifold
                    .step(start, end)
                    .is_some_and(|q| (q - end).norm() < MET_RAD)
            {
                return Some(vec![*start, *end]);
            }
        }
    }
    let robot = manifold.robot;
    let mut trees = [
        Tree::rooted(from, robot.dof()),
        Tree::rooted(to, robot.dof()),
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let limits = robot.limits();
    for draw in 0..config.samples {
        let guess = robot.configuration_from_fn(|i| {
            limits.lower[i] + rng.random::<f64>() * (limits.upper[i] - limits.lower[i])
        });
        let Some(sample) = manifold.project(&guess) else {
            continue;
        };
        let (growing, other) = if draw % 2 == 0 { (0, 1) } else { (1, 0) };
        let Some(reached) = trees[growing].grow_toward(manifold, &sample, STEPS_PER_DRAW) else {
            continue;
        };
        let reached_q = trees[growing].nodes[reached].q;
        if let Some(met) = trees[other].grow_toward(manifold, &reached_q, STEPS_PER_CONNECT)
            && (trees[other].nodes[met].q - reached_q).norm() < MET_RAD
        {
            let (from_end, to_end) = if growing == 0 {
                (reached, met)
            } else {
                (met, reached)
            };
            let mut motion = trees[0].path_to(from_end);
            motion.reverse();
            motion.extend(trees[1].path_to(to_end));
            return Some(motion);
        }
    }
    None
}

/// Where a [`Manifold`]'s configurations hold the TCP.
enum Hold {
    /// On one point.
    Point(Vec3),
    /// On the task's line, between these distances along it (m).
    Stretch { from_m: f64, to_m: f64 },
}

/// The configurations that put the TCP where [`Hold`] says and hold every constraint.
struct Manifold<'a> {
    robot: &'a Robot,
    task: &'a Task,
    constraints: &'a ConstraintConfig,
    hold: Hold,
    step_rad: f64,
}

impl Manifold<'_> {
    /// The configuration near `q` with the TCP on the point, or on the stretch's point nearest
    /// `q`'s TCP.
    fn project(&self, q: &JointVector) -> Option<JointVector> {
        let target = match self.hold {
            Hold::Point(point) => point,
            Hold::Stretch { from_m, to_m } => {
                let along = self.task.progress(&self.robot.forward(q).tcp());
                self.task.point_at(along.clamp(from_m, to_m))
            }
        };
        project_to_point(self.robot, q, &target)
    }

    /// Whether `q` holds every constraint.
    fn valid(&self, q: &JointVector) -> bool {
        first_violation(
            self.robot,
            self.task,
            &self.robot.forward(q),
            self.constraints,
        )
        .is_none()
    }

    /// One step from `from` toward `toward`: at most `step_rad` along the straight joint
    /// path, projected onto the manifold; `None` where the projection moves it more than twice
    /// that (it jumped to another sheet) or it or the midpoint of the step breaks a constraint.
    fn step(&self, from: &JointVector, toward: &JointVector) -> Option<JointVector> {
        let offset = toward - from;
        let length = offset.norm();
        let scale = if length > self.step_rad {
            self.step_rad / length
        } else {
            1.0
        };
        let next = self.project(&(from + offset * scale))?;
        if (next - from).norm() > 2.0 * self.step_rad || !self.valid(&next) {
            return None;
        }
        let midpoint = self.project(&((from + next) * 0.5))?;
        self.valid(&midpoint).then_some(next)
    }
}

/// A tree of configurations on the manifold, each node knowing its parent (roots none), with
/// a k-d tree of their joints to find the node nearest a configuration.
struct Tree {
    nodes: Vec<Node>,
    index: KdTree<f64, usize, Vec<f64>>,
    dof: usize,
}

struct Node {
    q: JointVector,
    parent: Option<usize>,
}

impl Tree {
    /// A tree of the configurations `roots` of an arm of `dof` joints, each a root.
    fn rooted(roots: &[JointVector], dof: usize) -> Self {
        let mut tree = Self {
            nodes: Vec::new(),
            index: KdTree::new(dof),
            dof,
        };
        for &q in roots {
            tree.add(Node { q, parent: None });
        }
        tree
    }

    /// Adds `node`; its index.
    fn add(&mut self, node: Node) -> usize {
        let at = self.nodes.len();
        self.index
            .add(node.q.as_slice()[..self.dof].to_vec(), at)
            .expect("configurations on the manifold are finite");
        self.nodes.push(node);
        at
    }

    /// Grows from the node nearest `target` toward it for at most `steps` steps; the last node
    /// added, `None` where not even one step was possible.
    fn grow_toward(
        &mut self,
        manifold: &Manifold,
        target: &JointVector,
        steps: usize,
    ) -> Option<usize> {
        let mut at = self.nearest(target);
        let mut added = None;
        for _ in 0..steps {
            let current = self.nodes[at].q;
            if (target - current).norm() < MET_RAD {
                break;
            }
            let Some(next) = manifold.step(&current, target) else {
                break;
            };
            at = self.add(Node {
                q: next,
                parent: Some(at),
            });
            added = Some(at);
        }
        added
    }

    /// The node nearest `target` (Euclidean over the joints).
    fn nearest(&self, target: &JointVector) -> usize {
        let nearest = self
            .index
            .nearest(&target.as_slice()[..self.dof], 1, &squared_euclidean)
            .expect("a finite configuration of the arm's joints");
        *nearest.first().expect("a tree has its root").1
    }

    /// The configurations from node `index` back to the root.
    fn path_to(&self, index: usize) -> Vec<JointVector> {
        let mut path = Vec::new();
        let mut at = Some(index);
        while let Some(i) = at {
            path.push(self.nodes[i].q);
            at = self.nodes[i].parent;
        }
        path
    }
}
