//! Nearest points among many (the stroke ends the order stage links): a uniform grid of cubic
//! cells holding about [`POINTS_PER_CELL`] points each, searched ring by ring outward from the
//! query's cell. Points may be removed. Every query counts the cells and points it visits, so
//! that the cost of a search is measured by work, not time.

use std::collections::HashMap;

use emg_kinematics::Vec3;

/// The ends of another stroke each stroke end keeps as candidates for a move.
pub const NEIGHBOURS: usize = 10;

/// The points an occupied cell holds on average, about.
const POINTS_PER_CELL: f64 = 2.0;

/// Halvings of the cell size tried when sizing the grid.
const SIZING_STEPS: usize = 40;

/// A cell's place in the grid.
type Key = [i64; 3];

/// Points in a uniform grid.
pub struct Grid {
    points: Vec<Vec3>,
    origin: Vec3,
    cell_m: f64,
    /// Cells along each axis, the last reaching the greatest coordinate.
    dims: [i64; 3],
    /// Each occupied cell's place in `cells`.
    index: HashMap<Key, usize>,
    /// The points in each occupied cell, in the order the grid was built.
    cells: Vec<Vec<usize>>,
    /// Where each point lies: its cell (`None` once removed).
    cell_of: Vec<Option<usize>>,
    live: usize,
    /// Cells and points visited by queries so far.
    work: usize,
}

impl Grid {
    /// The grid of `points`, its cells sized so that an occupied one holds about
    /// [`POINTS_PER_CELL`] of them.
    pub fn new(points: Vec<Vec3>) -> Self {
        let (origin, high) = points.iter().fold(
            (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
            |(low, high), p| (low.inf(p), high.sup(p)),
        );
        let span = (high - origin).max();
        let cell_m = if points.len() < 2 || span <= 0.0 {
            1.0
        } else {
            cell_size(&points, origin, span)
        };
        let mut grid = Self {
            origin,
            cell_m,
            dims: [0; 3],
            index: HashMap::new(),
            cells: Vec::new(),
            cell_of: vec![None; points.len()],
            live: points.len(),
            work: 0,
            points: Vec::new(),
        };
        if !points.is_empty() {
            grid.dims = grid.key(&high).map(|k| k + 1);
        }
        for (point, p) in points.iter().enumerate() {
            let next = grid.cells.len();
            let cell = *grid.index.entry(grid.key(p)).or_insert(next);
            if cell == next {
                grid.cells.push(Vec::new());
            }
            grid.cells[cell].push(point);
            grid.cell_of[point] = Some(cell);
        }
        grid.points = points;
        grid
    }

    /// Point `index` (as given to [`Grid::new`]).
    pub fn point(&self, index: usize) -> Vec3 {
        self.points[index]
    }

    /// Cells and points visited by the queries so far.
    pub fn work(&self) -> usize {
        self.work
    }

    /// Whether point `index` is still in the grid (not removed).
    pub fn contains(&self, index: usize) -> bool {
        self.cell_of[index].is_some()
    }

    /// Takes point `index` out of later queries.
    pub fn remove(&mut self, index: usize) {
        if let Some(cell) = self.cell_of[index].take() {
            let members = &mut self.cells[cell];
            if let Some(slot) = members.iter().position(|&p| p == index) {
                members.swap_remove(slot);
            }
            self.live -= 1;
        }
    }

    /// The `k` points nearest `at` no farther than `within_m` that `accept` takes, nearest first
    /// (of equally near ones the lower index), with their distances.
    pub fn nearest(
        &mut self,
        at: Vec3,
        k: usize,
        within_m: f64,
        accept: impl Fn(usize) -> bool,
    ) -> Vec<(f64, usize)> {
        let mut found: Vec<(f64, usize)> = Vec::with_capacity(k + 1);
        if k == 0 || self.live == 0 {
            return found;
        }
        let consider = |found: &mut Vec<(f64, usize)>, point: usize, p: Vec3| {
            let distance = (p - at).norm();
            if distance > within_m || !accept(point) {
                return;
            }
            let rank = found.partition_point(|&(d, i)| (d, i) < (distance, point));
            if rank < k {
                found.insert(rank, (distance, point));
                found.truncate(k);
            }
        };
        let centre = self.key(&at);
        // How far `at` lies outside its cell (where it lies outside the grid).
        let low = self.origin + Vec3::from(centre.map(|c| c as f64)) * self.cell_m;
        let outside = (low - at)
            .sup(&(at - low.add_scalar(self.cell_m)))
            .sup(&Vec3::zeros())
            .norm();
        // Cells visited ring by ring; past as many as hold points, every point is read instead.
        let mut cells_visited = 0;
        for ring in 0.. {
            // Every point not yet seen lies at least this far away.
            let nearest_unseen = ((ring as f64 - 1.0) * self.cell_m - outside).max(0.0);
            let full = found.len() == k && found[k - 1].0 <= nearest_unseen;
            if full || nearest_unseen > within_m || ring > self.dims.into_iter().max().unwrap_or(0)
            {
                break;
            }
            let cells = self.ring(centre, ring);
            if cells_visited + cells.len() > self.cells.len() {
                found.clear();
                self.work += self.points.len();
                for point in 0..self.points.len() {
                    if self.cell_of[point].is_some() {
                        consider(&mut found, point, self.points[point]);
                    }
                }
                return found;
            }
            cells_visited += cells.len();
            for key in cells {
                self.work += 1;
                if let Some(&cell) = self.index.get(&key) {
                    for &point in &self.cells[cell] {
                        self.work += 1;
                        consider(&mut found, point, self.points[point]);
                    }
                }
            }
        }
        found
    }

    /// The cell holding `p` (clamped to the grid).
    fn key(&self, p: &Vec3) -> Key {
        let offset = (p - self.origin) / self.cell_m;
        let axis = |i: usize| {
            let k = offset[i].floor().max(0.0) as i64;
            if self.dims[i] > 0 {
                k.min(self.dims[i] - 1)
            } else {
                k
            }
        };
        [axis(0), axis(1), axis(2)]
    }

    /// The cells of the grid `ring` cells from `centre` (its Chebyshev ring).
    fn ring(&self, centre: Key, ring: i64) -> Vec<Key> {
        let range = |axis: usize| {
            (centre[axis] - ring).max(0)..=(centre[axis] + ring).min(self.dims[axis] - 1)
        };
        let mut keys = Vec::new();
        for x in range(0) {
            for y in range(1) {
                let on_ring = (x - centre[0]).abs() == ring || (y - centre[1]).abs() == ring;
                for z in range(2) {
                    if on_ring || (z - centre[2]).abs() == ring {
                        keys.push([x, y, z]);
                    }
                }
            }
        }
        keys
    }
}

/// The cell size (m) at which about one cell in [`POINTS_PER_CELL`] points is occupied: halved
/// from `span`, the largest extent, while the points fill few enough cells.
fn cell_size(points: &[Vec3], origin: Vec3, span: f64) -> f64 {
    let wanted = (points.len() as f64 / POINTS_PER_CELL).ceil() as usize;
    let occupied = |cell_m: f64| {
        let mut keys: Vec<Key> = points
            .iter()
            .map(|p| ((p - origin) / cell_m).map(|c| c.floor() as i64).into())
            .collect();
        keys.sort_unstable();
        keys.dedup();
        keys.len()
    };
    let mut cell_m = span;
    for _ in 0..SIZING_STEPS {
        if occupied(cell_m / 2.0) > wanted {
            break;
        }
        cell_m /= 2.0;
    }
    cell_m
}

#[cfg(test)]
mod tests {
    use super::*;

    use rand::{RngExt, SeedableRng};

    /// The nearest points by looking at every one.
    fn brute(points: &[Vec3], at: Vec3, k: usize, within_m: f64) -> Vec<(f64, usize)> {
        let mut all: Vec<(f64, usize)> = points
            .iter()
            .enumerate()
            .map(|(i, p)| ((p - at).norm(), i))
            .filter(|&(d, _)| d <= within_m)
            .collect();
        all.sort_by(|a, b| a.partial_cmp(b).unwrap());
        all.truncate(k);
        all
    }

    #[test]
    fn the_grid_finds_the_nearest_points_as_a_search_of_all_would() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        // Points in a thin slab, and a few far off.
        let mut points: Vec<Vec3> = (0..400)
            .map(|_| Vec3::new(rng.random(), rng.random(), 0.001 * rng.random::<f64>()))
            .collect();
        points.push(Vec3::new(5.0, 5.0, 5.0));
        points.push(Vec3::new(-3.0, 0.5, 0.0));
        let mut grid = Grid::new(points.clone());
        for (i, &at) in points.iter().enumerate().step_by(7) {
            for (k, within) in [(1, f64::INFINITY), (8, f64::INFINITY), (5, 0.05)] {
                let near = grid.nearest(at, k, within, |p| p != i);
                let mut expected = brute(&points, at, k + 1, within);
                expected.retain(|&(_, p)| p != i);
                expected.truncate(k);
                assert_eq!(near, expected, "point {i}, k {k}");
            }
        }
        // Removed points are no longer found.
        for i in 0..300 {
            grid.remove(i);
        }
        let near = grid.nearest(points[0], 3, f64::INFINITY, |_| true);
        assert_eq!(
            near,
            brute(&points[300..], points[0], 3, f64::INFINITY)
                .into_iter()
                .map(|(d, i)| (d, i + 300))
                .collect::<Vec<_>>()
        );
        assert!(grid.work() > 0);
    }

    #[test]
    fn a_grid_of_one_point_or_of_none_answers() {
        let mut grid = Grid::new(vec![Vec3::new(1.0, 2.0, 3.0)]);
        assert_eq!(
            grid.nearest(Vec3::zeros(), 2, f64::INFINITY, |_| true)
                .len(),
            1
        );
        grid.remove(0);
        assert!(
            grid.nearest(Vec3::zeros(), 2, f64::INFINITY, |_| true)
                .is_empty()
        );
        let mut empty = Grid::new(Vec::new());
        assert!(
            empty
                .nearest(Vec3::zeros(), 1, f64::INFINITY, |_| true)
                .is_empty()
        );
    }
}
