//! A task's metric: the distance between two states and the states between them, each
//! space contributing its own part (weighted, for the distance) of the flat state.

use crate::space::StateSpace;

/// The distance and interpolation over a task's spaces, in order.
#[derive(Debug, Clone, Copy)]
pub struct Metric<'a> {
    /// The spaces whose values make up a state, in order.
    pub spaces: &'a [StateSpace],
}

impl Metric<'_> {
    /// Each space with its part of state `s`.
    pub fn parts<'s>(&self, s: &'s [f64]) -> impl Iterator<Item = (&StateSpace, &'s [f64])> {
        let mut at = 0;
        self.spaces.iter().map(move |sp| {
            let n = sp.kind.dimension();
            let part = &s[at..at + n];
            at += n;
            (sp, part)
        })
    }

    /// The weighted sum of the spaces' distances between `a` and `b`.
    pub fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        self.parts(a)
            .zip(self.parts(b))
            .map(|((sp, x), (_, y))| sp.weight * sp.distance(x, y))
            .sum()
    }

    /// The state a fraction `t` of the way from `a` to `b`, space by space.
    pub fn interpolate(&self, a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
        let mut out = Vec::with_capacity(a.len());
        for ((sp, x), (_, y)) in self.parts(a).zip(self.parts(b)) {
            sp.interpolate(x, y, t, &mut out);
        }
        out
    }
}
