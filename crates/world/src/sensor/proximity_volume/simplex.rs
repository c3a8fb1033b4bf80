//! The GJK simplex of `gjk.rs` (up to four points of the Minkowski difference `S - probe`,
//! in f64) and Ericson's Voronoi-region search for its point closest to the origin
//! ("Real-Time Collision Detection", 5.1.5–5.1.6), guarded against the flat simplices that thin
//! shapes produce.

use crate::math::Vec3;

/// A vertex of the GJK simplex: the point `w = x - y` of the Minkowski difference
/// `S - probe`, with its witnesses `x ∈ S` and `y ∈ probe`.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct CsoVertex {
    /// `x - y` (m).
    pub(super) w: Vec3,
    /// Witness on the shape (sensor frame, m).
    pub(super) x: Vec3,
    /// Witness on the probe (sensor frame, m).
    pub(super) y: Vec3,
}

/// A GJK simplex (up to 4 vertices), kept between calls to warm-start the next one.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Simplex {
    /// The vertices; only the first `len` are meaningful.
    pub(super) vertices: [CsoVertex; 4],
    /// Number of vertices, 0 (empty, not started) to 4.
    pub(super) len: usize,
}

impl Simplex {
    /// Re-targets the simplex at the sector scaled by `ratio`: support points of `k·Q` are
    /// `k` times those of `Q` in the same direction, so every vertex stays a valid point of the
    /// new Minkowski difference and GJK resumes close to the answer.
    pub(super) fn rescale_probe(&mut self, ratio: f64) {
        for vertex in &mut self.vertices[..self.len] {
            vertex.y *= ratio;
            vertex.w = vertex.x - vertex.y;
        }
    }
}

/// The closest point to the origin of a simplex's hull: the point, the indices of the
/// vertices of the face holding it and their barycentric weights (unused slots weigh 0).
pub(super) type SimplexPoint = (Vec3, [usize; 3], [f64; 3]);

/// Closest point to the origin of the hull of `simplex`, or `None` when the origin is inside
/// a (non-flat) tetrahedron, i.e. the shapes overlap. Does not modify the simplex; see
/// [`keep_face`].
pub(super) fn closest_on_simplex(simplex: &Simplex) -> Option<SimplexPoint> {
    let w: [Vec3; 4] = core::array::from_fn(|i| simplex.vertices[i].w);
    match simplex.len {
        1 => Some((w[0], [0, 0, 0], [1.0, 0.0, 0.0])),
        2 => Some(closest_on_segment(w, 0, 1)),
        3 => Some(closest_on_triangle(w, [0, 1, 2])),
        _ => {
            // The four faces with the index of the vertex opposite to each.
            const FACES: [([usize; 3], usize); 4] = [([0, 1, 2], 3), ([0, 2, 3], 1), ([0, 3, 1], 2), ([1, 3, 2], 0)];
            // The origin is outside iff some face plane separates it from the opposite vertex
            // (or the tetrahedron is flat). The closest point is then on the faces; all four
            // are searched, because with nearly flat tetrahedra the sign tests can pick the
            // wrong face, which stalls GJK on grazing contacts.
            let outside = FACES.iter().any(|&(face, opposite)| {
                let [a, b, c] = face.map(|i| w[i]);
                let n = (b - a).cross(&(c - a));
                let to_opposite = w[opposite] - a;
                let side_opposite = to_opposite.dot(&n);
                let flat = side_opposite * side_opposite <= 1.0e-24 * n.norm_squared() * to_opposite.norm_squared();
                flat || -a.dot(&n) * side_opposite < 0.0
            });
            if !outside {
                return None;
            }
            let mut best: Option<SimplexPoint> = None;
            for (face, _) in FACES {
                let candidate = closest_on_triangle(w, face);
                if best.is_none_or(|b| candidate.0.norm_squared() < b.0.norm_squared()) {
                    best = Some(candidate);
                }
            }
            best
        }
    }
}

/// Reduces the simplex to the face of `found` (see [`closest_on_simplex`]), dropping the
/// vertices of zero weight; returns the barycentric coordinates in the new vertex order.
pub(super) fn keep_face(simplex: &mut Simplex, found: &SimplexPoint) -> [f64; 4] {
    let (_, used, lambda) = *found;
    let old = simplex.vertices;
    let count = simplex.len.min(3);
    let mut bary = [0.0; 4];
    let mut n = 0;
    for k in 0..count {
        if lambda[k] > 0.0 {
            simplex.vertices[n] = old[used[k]];
            bary[n] = lambda[k];
            n += 1;
        }
    }
    if n == 0 {
        simplex.vertices[0] = old[used[0]];
        bary[0] = 1.0;
        n = 1;
    }
    simplex.len = n;
    bary
}

/// Closest point to the origin on the segment `[w[i], w[j]]`: the point, the two vertex
/// indices and their weights (padded to three).
fn closest_on_segment(w: [Vec3; 4], i: usize, j: usize) -> (Vec3, [usize; 3], [f64; 3]) {
    let (a, b) = (w[i], w[j]);
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 { -a.dot(&ab) / len2 } else { 0.0 };
    if t <= 0.0 {
        (a, [i, j, j], [1.0, 0.0, 0.0])
    } else if t >= 1.0 {
        (b, [i, j, j], [0.0, 1.0, 0.0])
    } else {
        (a + ab * t, [i, j, j], [1.0 - t, t, 0.0])
    }
}

/// Closest point to the origin on the triangle `w[face]` (Ericson's region tests): the point,
/// the vertex indices and their weights.
fn closest_on_triangle(w: [Vec3; 4], face: [usize; 3]) -> (Vec3, [usize; 3], [f64; 3]) {
    let [ia, ib, ic] = face;
    let (a, b, c) = (w[ia], w[ib], w[ic]);
    let ab = b - a;
    let ac = c - a;
    let d1 = -ab.dot(&a);
    let d2 = -ac.dot(&a);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, face, [1.0, 0.0, 0.0]);
    }
    let d3 = -ab.dot(&b);
    let d4 = -ac.dot(&b);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, face, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let t = d1 / (d1 - d3);
        return (a + ab * t, face, [1.0 - t, t, 0.0]);
    }
    let d5 = -ab.dot(&c);
    let d6 = -ac.dot(&c);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, face, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let t = d2 / (d2 - d6);
        return (a + ac * t, face, [1.0 - t, 0.0, t]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * t, face, [0.0, 1.0 - t, t]);
    }
    let sum = va + vb + vc;
    if sum <= 0.0 || !sum.is_finite() {
        // Degenerate (flat) triangle: the closest point is on one of its edges.
        let edges = [
            closest_on_segment(w, ia, ib),
            closest_on_segment(w, ib, ic),
            closest_on_segment(w, ia, ic),
        ];
        let mut best = edges[0];
        for e in &edges[1..] {
            if e.0.norm_squared() < best.0.norm_squared() {
                best = *e;
            }
        }
        return best;
    }
    let v = vb / sum;
    let t = vc / sum;
    (a + ab * v + ac * t, face, [1.0 - v - t, v, t])
}
