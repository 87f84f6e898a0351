//! Balls bounding runs of a path's pieces, in a binary tree over their order along the path, so
//! that the nearest point of a path of many pieces is found looking at few of them: a run
//! whose ball lies farther from the point than the nearest point found so far cannot hold a
//! nearer one.

use emg_kinematics::Vec3;

/// Pieces a leaf of the tree holds at most.
const LEAF_PIECES: usize = 8;

/// A ball holding every point of a run of pieces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Ball {
    centre: Vec3,
    radius: f64,
}

impl Ball {
    /// The ball holding a curve of `length_m` whose point halfway along its length is
    /// `middle`: no point of the curve is farther from it than half the length along the
    /// curve, so not farther in space (widened by a rounding margin).
    pub(super) fn of_curve(middle: Vec3, length_m: f64) -> Self {
        Self {
            centre: middle,
            radius: 0.5 * length_m * (1.0 + 1e-9) + 1e-12,
        }
    }

    /// The least ball holding both.
    fn around(a: &Self, b: &Self) -> Self {
        let offset = b.centre - a.centre;
        let distance = offset.norm();
        if distance + b.radius <= a.radius {
            return *a;
        }
        if distance + a.radius <= b.radius {
            return *b;
        }
        let radius = 0.5 * (distance + a.radius + b.radius);
        Self {
            centre: a.centre + offset * ((radius - a.radius) / distance),
            radius: radius * (1.0 + 1e-12),
        }
    }

    /// A lower bound on the distance from `p` to every point in the ball.
    pub(super) fn distance_below(&self, p: &Vec3) -> f64 {
        ((p - self.centre).norm() - self.radius).max(0.0)
    }
}

/// A node: the ball of the pieces `first..end`, and its two halves unless it is a leaf.
#[derive(Clone, Debug, PartialEq)]
struct Node {
    ball: Ball,
    first: usize,
    end: usize,
    halves: Option<[usize; 2]>,
}

/// The tree of balls over a path's pieces in order (empty for a path of no piece).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct PieceTree {
    nodes: Vec<Node>,
}

impl PieceTree {
    /// The tree over pieces bounded by `balls`, in the path's order.
    pub(super) fn new(balls: &[Ball]) -> Self {
        let mut tree = Self { nodes: Vec::new() };
        if !balls.is_empty() {
            tree.build(balls, 0, balls.len());
        }
        tree
    }

    /// Adds the node of pieces `first..end` and those below it; its index.
    fn build(&mut self, balls: &[Ball], first: usize, end: usize) -> usize {
        let index = self.nodes.len();
        let ball = balls[first + 1..end]
            .iter()
            .fold(balls[first], |ball, next| Ball::around(&ball, next));
        self.nodes.push(Node {
            ball,
            first,
            end,
            halves: None,
        });
        if end - first > LEAF_PIECES {
            let middle = first + (end - first) / 2;
            let low = self.build(balls, first, middle);
            let high = self.build(balls, middle, end);
            self.nodes[index].halves = Some([low, high]);
        }
        index
    }

    /// Calls `look` on every piece that may hold a point nearer `p` than `best()` (the
    /// distance of the nearest point found so far, which `look` may lower), the nearer
    /// halves first; pieces no nearer than `best()` by their balls are not looked at.
    pub(super) fn visit(&self, p: &Vec3, best: &dyn Fn() -> f64, look: &mut dyn FnMut(usize)) {
        if !self.nodes.is_empty() {
            self.visit_node(0, p, best, look);
        }
    }

    fn visit_node(
        &self,
        index: usize,
        p: &Vec3,
        best: &dyn Fn() -> f64,
        look: &mut dyn FnMut(usize),
    ) {
        let node = &self.nodes[index];
        if node.ball.distance_below(p) > best() {
            return;
        }
        match node.halves {
            None => (node.first..node.end).for_each(&mut *look),
            Some([low, high]) => {
                let below = |k: usize| self.nodes[k].ball.distance_below(p);
                let (near, far) = if below(high) < below(low) {
                    (high, low)
                } else {
                    (low, high)
                };
                self.visit_node(near, p, best, look);
                self.visit_node(far, p, best, look);
            }
        }
    }
}
