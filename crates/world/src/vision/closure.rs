//! Which triangles of an imported mesh lie on closed surfaces wound outwards: the
//! triangles whose back faces the rasteriser may skip.
//!
//! Vendor meshes are not reliably closed (open shells, T-junctions, parts that touch),
//! so the mesh as a whole is not trusted; instead it is cut into its connected
//! components (triangles sharing an edge, vertices welded by bit-equal position), and a
//! component counts as closed when each of its directed edges `a -> b` appears exactly
//! once and its reverse `b -> a` exactly once (every edge shared by two triangles that
//! agree on the winding, no edge shared by three), and as outward when its signed
//! volume is positive. For such a component, seen from outside, every back-facing
//! triangle lies behind one of its front-facing triangles, so skipping back faces
//! changes no pixel except, by rounding, where a front and a back face meet at a
//! silhouette (the renderer only skips them when the eye is outside: see
//! `raster::draw_visual`).

/// Per triangle of `triangles` (indices into `positions`), whether it lies on a closed,
/// outward-wound component. Triangles with two corners at one position have no area
/// and count as closed (they draw nothing either way).
pub(crate) fn closed_triangles(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<bool> {
    // Sorting rather than hashing throughout: several times faster on a vendor mesh's
    // 10,000-100,000 triangles, and tessellation happens on a sensor's first frame.
    // Weld: one id per distinct position (bit for bit).
    let key = |i: u32| positions.get(i as usize).map_or([u32::MAX; 3], |p| p.map(f32::to_bits));
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.sort_unstable_by_key(|&i| key(i));
    let mut id = vec![0u32; positions.len()];
    for pair in order.windows(2) {
        id[pair[1] as usize] = id[pair[0] as usize] + u32::from(key(pair[0]) != key(pair[1]));
    }
    let welded: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| t.map(|i| id.get(i as usize).copied().unwrap_or(u32::MAX)))
        .collect();
    let degenerate = |[a, b, c]: [u32; 3]| a == b || b == c || c == a;
    let sides = |t: [u32; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];

    // Directed edges, sorted, with the triangle each comes from.
    let mut directed: Vec<(u32, u32, u32)> = Vec::with_capacity(3 * triangles.len());
    for (k, &t) in welded.iter().enumerate().filter(|(_, t)| !degenerate(**t)) {
        directed.extend(sides(t).map(|(a, b)| (a, b, k as u32)));
    }
    directed.sort_unstable();
    let count = |a: u32, b: u32| {
        let lo = directed.partition_point(|e| (e.0, e.1) < (a, b));
        let hi = directed.partition_point(|e| (e.0, e.1) <= (a, b));
        hi - lo
    };

    // Components: triangles joined through shared (undirected) edges.
    let mut parent: Vec<u32> = (0..triangles.len() as u32).collect();
    let mut undirected: Vec<(u32, u32, u32)> = directed.iter().map(|&(a, b, k)| (a.min(b), a.max(b), k)).collect();
    undirected.sort_unstable();
    for pair in undirected.windows(2) {
        if (pair[0].0, pair[0].1) == (pair[1].0, pair[1].1) {
            union(&mut parent, pair[0].2, pair[1].2);
        }
    }

    // Per component root: closed so far, and six times its signed volume (f64).
    let mut closed = vec![(true, 0.0f64); triangles.len()];
    for (k, &t) in welded.iter().enumerate() {
        if degenerate(t) {
            continue;
        }
        let root = find(&mut parent, k as u32) as usize;
        let edges_ok = sides(t).iter().all(|&(a, b)| count(a, b) == 1 && count(b, a) == 1);
        let [a, b, c] = triangles[k].map(|i| positions.get(i as usize).copied().unwrap_or([0.0; 3]).map(f64::from));
        // a . (b x c): six times the signed volume of the tetrahedron with the origin.
        let volume = a[0] * (b[1] * c[2] - b[2] * c[1])
            + a[1] * (b[2] * c[0] - b[0] * c[2])
            + a[2] * (b[0] * c[1] - b[1] * c[0]);
        closed[root].0 &= edges_ok;
        closed[root].1 += volume;
    }
    (0..triangles.len())
        .map(|k| {
            degenerate(welded[k]) || {
                let (ok, volume) = closed[find(&mut parent, k as u32) as usize];
                ok && volume > 0.0
            }
        })
        .collect()
}

/// The root of `x`'s set, halving the path on the way.
fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up;
        x = up;
    }
    x
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    // The smaller index as root: the result does not depend on hashing order.
    let (lo, hi) = (ra.min(rb), ra.max(rb));
    parent[hi as usize] = lo;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube's 12 triangles wound outwards (`flip`: inwards), vertices shared.
    fn cube(offset: f32, flip: bool) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let p: Vec<[f32; 3]> = (0..8)
            .map(|i| [(i & 1) as f32 + offset, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
            .collect();
        // Quads counter-clockwise seen from outside.
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let mut t = Vec::new();
        for [a, b, c, d] in quads {
            for tri in [[a, b, c], [a, c, d]] {
                t.push(if flip { [tri[0], tri[2], tri[1]] } else { tri });
            }
        }
        (p, t)
    }

    #[test]
    fn a_closed_outward_cube_is_closed_and_an_inward_one_is_not() {
        let (p, t) = cube(0.0, false);
        assert!(closed_triangles(&p, &t).iter().all(|&c| c));
        let (p, t) = cube(0.0, true);
        assert!(closed_triangles(&p, &t).iter().all(|&c| !c));
    }

    #[test]
    fn components_are_judged_apart() {
        // A closed cube, then an open one (one triangle missing) beside it, with
        // positions duplicated per triangle as a flat-shaded mesh has them.
        let (p0, t0) = cube(0.0, false);
        let (p1, mut t1) = cube(3.0, false);
        t1.pop();
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for (p, t) in [(&p0, &t0), (&p1, &t1)] {
            for tri in t {
                let base = positions.len() as u32;
                positions.extend(tri.map(|i| p[i as usize]));
                triangles.push([base, base + 1, base + 2]);
            }
        }
        let closed = closed_triangles(&positions, &triangles);
        assert!(closed[..12].iter().all(|&c| c));
        assert!(closed[12..].iter().all(|&c| !c));
    }

    #[test]
    fn an_edge_shared_by_three_triangles_or_a_flipped_one_opens_the_component() {
        let (p, mut t) = cube(0.0, false);
        // A fin on the edge 0-2 of the bottom face: that edge now has three triangles.
        let mut p = p;
        p.push([0.0, 0.5, -1.0]);
        t.push([0, 2, 8]);
        assert!(closed_triangles(&p, &t).iter().all(|&c| !c));
        let (p, mut t) = cube(0.0, false);
        t[0] = [t[0][0], t[0][2], t[0][1]];
        assert!(closed_triangles(&p, &t).iter().all(|&c| !c));
    }
}
