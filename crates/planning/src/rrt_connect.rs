//! RRT-Connect (Kuffner and LaValle, 2000): two trees, one from the start and one from
//! the goals, each step extending one towards a random state and then pulling the other
//! towards the new state until they meet. Probabilistically complete, and the planner
//! OMPL's users reach for first.
//!
//! The algorithm only sees states as flat `f64` slices, through [`Problem`]; the world
//! answers with the scene (`gantry_world::planning`), the tests with a toy square.

use crate::rng::Rng;

/// What the planner asks of the problem.
pub trait Problem {
    /// A random state.
    fn sample(&mut self, rng: &mut Rng) -> Vec<f64>;
    /// The distance between two states.
    fn distance(&self, a: &[f64], b: &[f64]) -> f64;
    /// The state a fraction `t` of the way from `a` to `b`.
    fn interpolate(&self, a: &[f64], b: &[f64], t: f64) -> Vec<f64>;
    /// Whether the straight motion from `a` (valid) to `b` stays valid.
    fn motion_valid(&mut self, a: &[f64], b: &[f64]) -> bool;
    /// Whether the planner must give up (time is out).
    fn out_of_time(&self) -> bool;
}

struct Tree {
    states: Vec<Vec<f64>>,
    parents: Vec<Option<usize>>,
}

impl Tree {
    fn new(roots: &[Vec<f64>]) -> Self {
        Self {
            states: roots.to_vec(),
            parents: vec![None; roots.len()],
        }
    }

    fn nearest(&self, p: &dyn Problem, q: &[f64]) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, s) in self.states.iter().enumerate() {
            let d = p.distance(s, q);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// The states from node `i` up to its root.
    fn branch(&self, mut i: usize) -> Vec<Vec<f64>> {
        let mut out = vec![self.states[i].clone()];
        while let Some(parent) = self.parents[i] {
            out.push(self.states[parent].clone());
            i = parent;
        }
        out
    }
}

enum Extend {
    Reached(usize),
    Advanced(usize),
    Trapped,
}

/// One step of `tree` towards `q`, at most `range` long.
fn extend(tree: &mut Tree, p: &mut dyn Problem, q: &[f64], range: f64) -> Extend {
    let near = tree.nearest(p, q);
    let d = p.distance(&tree.states[near], q);
    let (new, reached) = if d <= range {
        (q.to_vec(), true)
    } else {
        (p.interpolate(&tree.states[near], q, range / d), false)
    };
    if !p.motion_valid(&tree.states[near], &new) {
        return Extend::Trapped;
    }
    tree.states.push(new);
    tree.parents.push(Some(near));
    let i = tree.states.len() - 1;
    if reached {
        Extend::Reached(i)
    } else {
        Extend::Advanced(i)
    }
}

/// A path from `start` to one of `goals` (all valid states), or `None` when the time
/// ran out first. Steps are at most `range` long.
pub fn plan(
    p: &mut dyn Problem,
    start: &[f64],
    goals: &[Vec<f64>],
    range: f64,
    rng: &mut Rng,
) -> Option<Vec<Vec<f64>>> {
    let mut a = Tree::new(&[start.to_vec()]);
    let mut b = Tree::new(goals);
    // Whether `a` grows from the start (the trees swap roles every iteration).
    let mut a_is_start = true;
    // A start that sees a goal directly needs no tree.
    for g in goals {
        if p.motion_valid(start, g) {
            return Some(vec![start.to_vec(), g.clone()]);
        }
    }
    while !p.out_of_time() {
        let q = p.sample(rng);
        let new = match extend(&mut a, p, &q, range) {
            Extend::Trapped => None,
            Extend::Reached(i) | Extend::Advanced(i) => Some(i),
        };
        if let Some(i) = new {
            let target = a.states[i].clone();
            loop {
                match extend(&mut b, p, &target, range) {
                    Extend::Advanced(_) => continue,
                    Extend::Trapped => break,
                    Extend::Reached(j) => {
                        let (from_a, from_b) = (a.branch(i), b.branch(j));
                        // `from_b` starts with the meeting state, also `from_a`'s first.
                        let mut path: Vec<Vec<f64>> = from_a.into_iter().rev().collect();
                        path.extend(from_b.into_iter().skip(1));
                        if !a_is_start {
                            path.reverse();
                        }
                        return Some(path);
                    }
                }
            }
        }
        std::mem::swap(&mut a, &mut b);
        a_is_start = !a_is_start;
    }
    None
}

/// Shortens `path` by joining random pairs of its states directly when the motion
/// between them is valid (`tries` attempts), keeping its ends.
pub fn shortcut(p: &mut dyn Problem, path: &mut Vec<Vec<f64>>, tries: usize, rng: &mut Rng) {
    for _ in 0..tries {
        if path.len() < 3 || p.out_of_time() {
            return;
        }
        let i = rng.below(path.len() - 2);
        let j = i + 2 + rng.below(path.len() - i - 2);
        if p.motion_valid(&path[i], &path[j]) {
            path.drain(i + 1..j);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit square with a wall at x = 0.5 from y = 0 to 0.8.
    struct Wall {
        checks: usize,
    }

    impl Wall {
        fn free(q: &[f64]) -> bool {
            !((q[0] - 0.5).abs() < 0.05 && q[1] < 0.8)
        }
    }

    impl Problem for Wall {
        fn sample(&mut self, rng: &mut Rng) -> Vec<f64> {
            vec![rng.unit(), rng.unit()]
        }
        fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
        }
        fn interpolate(&self, a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
            vec![a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
        }
        fn motion_valid(&mut self, a: &[f64], b: &[f64]) -> bool {
            (0..=100).all(|k| {
                self.checks += 1;
                Self::free(&self.interpolate(a, b, f64::from(k) / 100.0))
            })
        }
        fn out_of_time(&self) -> bool {
            self.checks > 10_000_000
        }
    }

    #[test]
    fn a_path_goes_around_the_wall_and_is_the_same_in_every_run() {
        let run = || {
            let mut p = Wall { checks: 0 };
            let mut rng = Rng::new(7);
            let mut path = plan(&mut p, &[0.1, 0.1], &[vec![0.9, 0.1]], 0.1, &mut rng).expect("a path");
            shortcut(&mut p, &mut path, 100, &mut rng);
            path
        };
        let path = run();
        assert_eq!(path.first().unwrap(), &vec![0.1, 0.1]);
        assert_eq!(path.last().unwrap(), &vec![0.9, 0.1]);
        let mut p = Wall { checks: 0 };
        for w in path.windows(2) {
            assert!(p.motion_valid(&w[0], &w[1]), "segment {w:?} crosses the wall");
        }
        assert!(
            path.iter().any(|q| q[1] >= 0.8),
            "the path passes above the wall: {path:?}"
        );
        assert_eq!(run(), path, "the same seed gives the same path");
    }

    #[test]
    fn a_goal_in_sight_is_reached_directly() {
        let mut p = Wall { checks: 0 };
        let path = plan(&mut p, &[0.1, 0.9], &[vec![0.9, 0.9]], 0.1, &mut Rng::new(1)).unwrap();
        assert_eq!(path, vec![vec![0.1, 0.9], vec![0.9, 0.9]]);
    }
}
