//! Forman's discrete gradient on a triangulated surface by ProcessLowerStars (Robins, Wood &
//! Sheppard 2011), applied to simplicial lower stars, with one cone per boundary loop
//! (NOTES.md 1).
//!
//! The cone vertices enter the filtration last, so the 0-dimensional structure of the real
//! vertices is unchanged while boundary minima become interior minima of a closed surface.
//! The *descending* structure is the gradient of the SoS order (minima are its critical
//! vertices); the *ascending* one is the gradient of the reversed order with the cones still
//! last (its critical vertices are the maxima, boundary maxima included).
//!
//! ```
//! use toposmooth::{domain::Grid2d, topology::gradient::{Direction, DiscreteGradient}};
//! let g = Grid2d::new(3, 3)?;
//! let h = [0.0, 1.0, 0.0, 1.0, 2.0, 1.0, 0.0, 1.0, 0.0];
//! let down = DiscreteGradient::new(&g, &h, Direction::Descending);
//! assert_eq!(down.critical_vertices(), vec![0, 2, 6, 8]); // four corner minima
//! assert_eq!(down.euler_characteristic(), 2); // the coned grid is a sphere
//! # Ok::<(), toposmooth::Error>(())
//! ```

use crate::domain::{sos_sort, Domain};
use std::collections::HashMap;

/// Which structure to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// SoS order: critical vertices are minima; V-paths descend.
    Descending,
    /// Reversed SoS order: critical vertices are maxima; V-paths ascend.
    Ascending,
}

/// What a cell is paired with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pairing {
    None,
    Critical,
    Cell(u32),
}

/// The coned complex: the domain's triangles plus one cone vertex per boundary loop joined to
/// each of its boundary edges; edges and incidences in compressed rows. Shared by the
/// descending and ascending gradients.
#[derive(Clone, Debug)]
pub struct Complex {
    n_real: usize,
    n_loops: usize,
    edges: Vec<[u32; 2]>,
    triangles: Vec<[u32; 3]>,
    vertex_edges: Csr,
    edge_triangles: Csr,
}

/// Compressed rows of `u32`.
#[derive(Clone, Debug, Default)]
struct Csr {
    start: Vec<usize>,
    items: Vec<u32>,
}

impl std::ops::Index<usize> for Csr {
    type Output = [u32];
    fn index(&self, i: usize) -> &[u32] {
        &self.items[self.start[i]..self.start[i + 1]]
    }
}

impl Csr {
    fn from_pairs(rows: usize, mut pairs: Vec<(u32, u32)>) -> Csr {
        pairs.sort_unstable();
        let mut start = vec![0usize; rows + 1];
        for &(r, _) in &pairs {
            start[r as usize + 1] += 1;
        }
        for i in 0..rows {
            start[i + 1] += start[i];
        }
        Csr { start, items: pairs.into_iter().map(|(_, x)| x).collect() }
    }
}

/// Edges of `triangles` by sorting (a, b, triangle): the edge list and, per edge, its
/// triangles.
fn edges_of(triangles: &[[u32; 3]]) -> (Vec<[u32; 2]>, Csr) {
    let mut keyed: Vec<(u64, u32)> = Vec::with_capacity(3 * triangles.len());
    for (ti, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
            keyed.push(((u64::from(a) << 32) | u64::from(b), ti as u32));
        }
    }
    keyed.sort_unstable();
    let mut edges: Vec<[u32; 2]> = Vec::new();
    let mut start = vec![0usize];
    let mut items = Vec::with_capacity(keyed.len());
    for (k, &(key, ti)) in keyed.iter().enumerate() {
        if k > 0 && keyed[k - 1].0 != key {
            start.push(items.len());
        }
        if k == 0 || keyed[k - 1].0 != key {
            edges.push([(key >> 32) as u32, key as u32]);
        }
        items.push(ti);
    }
    start.push(items.len());
    (edges, Csr { start, items })
}

impl Complex {
    /// Cones the domain's triangulation: one cone vertex `n + l` per boundary loop `l`.
    ///
    /// # Panics
    /// If the domain has no triangles.
    pub fn new<D: Domain>(domain: &D) -> Complex {
        let n = domain.n_vertices();
        let mut triangles: Vec<[u32; 3]> = domain.triangles().into_iter().map(|t| t.map(|v| v as u32)).collect();
        assert!(!triangles.is_empty(), "the discrete gradient needs a triangulated domain");
        // boundary loops: boundary edges have one triangle; walk them vertex to vertex
        let (edges, edge_triangles) = edges_of(&triangles);
        let boundary: Vec<[u32; 2]> =
            (0..edges.len()).filter(|&e| edge_triangles[e].len() == 1).map(|e| edges[e]).collect();
        let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
        for e in &boundary {
            next.entry(e[0]).or_default().push(e[1]);
            next.entry(e[1]).or_default().push(e[0]);
        }
        let mut loop_of: HashMap<u32, u32> = HashMap::new();
        let mut n_loops = 0u32;
        for e in &boundary {
            if loop_of.contains_key(&e[0]) {
                continue;
            }
            let mut stack = vec![e[0]];
            while let Some(v) = stack.pop() {
                if loop_of.insert(v, n_loops).is_none() {
                    stack.extend(next[&v].iter().copied());
                }
            }
            n_loops += 1;
        }
        for e in &boundary {
            triangles.push([e[0], e[1], n as u32 + loop_of[&e[0]]]);
        }
        let (edges, edge_triangles) = edges_of(&triangles);
        let n_all = n + n_loops as usize;
        let mut incidences = Vec::with_capacity(2 * edges.len());
        for (ei, e) in edges.iter().enumerate() {
            incidences.push((e[0], ei as u32));
            incidences.push((e[1], ei as u32));
        }
        let vertex_edges = Csr::from_pairs(n_all, incidences);
        Complex { n_real: n, n_loops: n_loops as usize, edges, triangles, vertex_edges, edge_triangles }
    }
}

/// A discrete gradient on a coned complex.
#[derive(Clone, Debug)]
pub struct DiscreteGradient {
    c: std::sync::Arc<Complex>,
    /// Filtration rank of every vertex (cones last).
    rank: Vec<u32>,
    vertex_pair: Vec<Pairing>,
    edge_pair: Vec<Pairing>,
    triangle_pair: Vec<Pairing>,
}

impl DiscreteGradient {
    /// Builds the coned complex of `domain` and runs ProcessLowerStars in the given direction.
    ///
    /// # Panics
    /// If `values.len() != domain.n_vertices()` or the domain has no triangles.
    pub fn new<D: Domain>(domain: &D, values: &[f64], direction: Direction) -> Self {
        assert_eq!(values.len(), domain.n_vertices());
        Self::on(std::sync::Arc::new(Complex::new(domain)), values, direction)
    }

    /// Runs ProcessLowerStars on an already coned complex.
    ///
    /// # Panics
    /// If `values` does not have one entry per real vertex.
    pub fn on(c: std::sync::Arc<Complex>, values: &[f64], direction: Direction) -> Self {
        let n = c.n_real;
        assert_eq!(values.len(), n);
        let n_all = n + c.n_loops;
        let mut order = sos_sort(values);
        if direction == Direction::Ascending {
            order.reverse();
        }
        let mut rank = vec![0u32; n_all];
        for (k, &v) in order.iter().enumerate() {
            rank[v] = k as u32;
        }
        for (l, r) in rank.iter_mut().enumerate().skip(n) {
            *r = l as u32;
        }
        let mut g = DiscreteGradient {
            rank,
            vertex_pair: vec![Pairing::None; n_all],
            edge_pair: vec![Pairing::None; c.edges.len()],
            triangle_pair: vec![Pairing::None; c.triangles.len()],
            c,
        };
        let mut by_rank: Vec<u32> = (0..n_all as u32).collect();
        by_rank.sort_by_key(|&v| g.rank[v as usize]);
        for v in by_rank {
            g.process_lower_star(v);
        }
        g
    }

    fn other(&self, e: u32, v: u32) -> u32 {
        let [a, b] = self.c.edges[e as usize];
        if a == v {
            b
        } else {
            a
        }
    }

    /// Ranks of a lower-star cell's vertices other than v, descending (the comparison key).
    fn key(&self, cell: Cell, v: u32) -> [u32; 2] {
        match cell {
            Cell::Edge(e) => [self.rank[self.other(e, v) as usize], 0],
            Cell::Triangle(t) => {
                let mut r = [0u32; 2];
                let mut k = 0;
                for &w in &self.c.triangles[t as usize] {
                    if w != v && k < 2 {
                        r[k] = self.rank[w as usize];
                        k += 1;
                    }
                }
                [r[0].max(r[1]), r[0].min(r[1]) + 1]
            }
        }
    }

    fn process_lower_star(&mut self, v: u32) {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        let rv = self.rank[v as usize];
        let lower_edges: Vec<u32> = self.c.vertex_edges[v as usize]
            .iter()
            .copied()
            .filter(|&e| self.rank[self.other(e, v) as usize] < rv)
            .collect();
        if lower_edges.is_empty() {
            self.vertex_pair[v as usize] = Pairing::Critical;
            return;
        }
        // the edge from v to w (a cone's star is a whole boundary loop: look it up by hash)
        let by_other: Option<HashMap<u32, u32>> =
            (lower_edges.len() > 16).then(|| lower_edges.iter().map(|&e| (self.other(e, v), e)).collect());
        let edge_to = |g: &Self, w: u32| -> u32 {
            match &by_other {
                Some(m) => m[&w],
                None => *lower_edges.iter().find(|&&e| g.other(e, v) == w).expect("a lower edge"),
            }
        };
        let in_star = |g: &Self, t: u32| g.c.triangles[t as usize].iter().all(|&w| g.rank[w as usize] <= rv);
        // faces of a lower-star triangle inside the lower star: its two edges at v
        let faces = |g: &Self, t: u32| -> [u32; 2] {
            let mut f = [0u32; 2];
            let mut k = 0;
            for &w in &g.c.triangles[t as usize] {
                if w != v && k < 2 {
                    f[k] = edge_to(g, w);
                    k += 1;
                }
            }
            f
        };
        let unpaired_faces =
            |g: &Self, t: u32| faces(g, t).iter().filter(|&&e| g.edge_pair[e as usize] == Pairing::None).count();
        let mut lower_triangles: Vec<u32> = Vec::new();
        for &e in &lower_edges {
            for &t in &self.c.edge_triangles[e as usize] {
                if in_star(self, t) {
                    lower_triangles.push(t);
                }
            }
        }
        lower_triangles.sort_unstable();
        lower_triangles.dedup();
        // cells keyed by the ranks of their other vertices, descending (edges before the
        // triangles that contain them); both queues drop stale entries when popped
        type Entry = Reverse<([u32; 2], u8, u32)>;
        let edge_entry = |g: &Self, e: u32| -> Entry { Reverse((g.key(Cell::Edge(e), v), 0, e)) };
        let triangle_entry = |g: &Self, t: u32| -> Entry { Reverse((g.key(Cell::Triangle(t), v), 1, t)) };
        // lower-star triangles with face e and one unpaired face go to the first queue
        let ready = |g: &Self, e: u32, pq_one: &mut BinaryHeap<Entry>| {
            for &t in &g.c.edge_triangles[e as usize] {
                if in_star(g, t) && g.triangle_pair[t as usize] == Pairing::None && unpaired_faces(g, t) == 1 {
                    pq_one.push(triangle_entry(g, t));
                }
            }
        };
        let delta = *lower_edges.iter().min_by_key(|&&e| self.key(Cell::Edge(e), v)).expect("non-empty");
        self.vertex_pair[v as usize] = Pairing::Cell(delta);
        self.edge_pair[delta as usize] = Pairing::Cell(v);
        let mut pq_zero: BinaryHeap<Entry> =
            lower_edges.iter().filter(|&&e| e != delta).map(|&e| edge_entry(self, e)).collect();
        let mut pq_one: BinaryHeap<Entry> = BinaryHeap::new();
        ready(self, delta, &mut pq_one);
        loop {
            while let Some(Reverse((_, _, alpha))) = pq_one.pop() {
                if self.triangle_pair[alpha as usize] != Pairing::None {
                    continue;
                }
                if unpaired_faces(self, alpha) == 0 {
                    pq_zero.push(triangle_entry(self, alpha));
                    continue;
                }
                let lower =
                    *faces(self, alpha).iter().find(|&&e| self.edge_pair[e as usize] == Pairing::None).expect("one");
                self.edge_pair[lower as usize] = Pairing::Cell(alpha);
                self.triangle_pair[alpha as usize] = Pairing::Cell(lower);
                ready(self, lower, &mut pq_one);
            }
            let Some(Reverse((_, kind, id))) = pq_zero.pop() else { break };
            if kind == 0 {
                if self.edge_pair[id as usize] != Pairing::None {
                    continue;
                }
                self.edge_pair[id as usize] = Pairing::Critical;
                ready(self, id, &mut pq_one);
            } else if self.triangle_pair[id as usize] == Pairing::None {
                self.triangle_pair[id as usize] = Pairing::Critical;
            }
        }
        // every lower-star triangle not reached is critical (both faces were paired elsewhere)
        for &t in &lower_triangles {
            if self.triangle_pair[t as usize] == Pairing::None {
                self.triangle_pair[t as usize] = Pairing::Critical;
            }
        }
        for &e in &lower_edges {
            if self.edge_pair[e as usize] == Pairing::None {
                self.edge_pair[e as usize] = Pairing::Critical;
            }
        }
    }

    /// Critical vertices among the real ones (minima when descending, maxima when ascending).
    pub fn critical_vertices(&self) -> Vec<usize> {
        (0..self.c.n_real).filter(|&v| self.vertex_pair[v] == Pairing::Critical).collect()
    }

    /// Critical edges (saddles) as vertex pairs; edges at a cone name the cone as `n + loop`.
    pub fn critical_edges(&self) -> Vec<[usize; 2]> {
        (0..self.c.edges.len())
            .filter(|&e| self.edge_pair[e] == Pairing::Critical)
            .map(|e| self.c.edges[e].map(|v| v as usize))
            .collect()
    }

    /// Number of critical cells of each dimension on the coned complex (cones included).
    pub fn critical_counts(&self) -> [usize; 3] {
        [
            self.vertex_pair.iter().filter(|p| **p == Pairing::Critical).count(),
            self.edge_pair.iter().filter(|p| **p == Pairing::Critical).count(),
            self.triangle_pair.iter().filter(|p| **p == Pairing::Critical).count(),
        ]
    }

    /// `#critical vertices − #critical edges + #critical triangles` (2 per closed component).
    pub fn euler_characteristic(&self) -> i64 {
        let [a, b, c] = self.critical_counts();
        a as i64 - b as i64 + c as i64
    }

    /// Whether every cell is paired exactly once or critical (a valid discrete vector field).
    pub fn is_complete(&self) -> bool {
        self.vertex_pair.iter().chain(&self.edge_pair).chain(&self.triangle_pair).all(|p| *p != Pairing::None)
    }

    /// For every vertex (cones included), the critical vertex its V-path ends at; each path
    /// is walked once (the ends of the vertices on it are filled on the way back).
    fn initial_path_ends(&self) -> Vec<u32> {
        const UNKNOWN: u32 = u32::MAX;
        let mut end = vec![UNKNOWN; self.vertex_pair.len()];
        let mut trail = Vec::new();
        for v in 0..end.len() as u32 {
            let mut x = v;
            while end[x as usize] == UNKNOWN {
                match self.vertex_pair[x as usize] {
                    Pairing::Cell(e) => {
                        trail.push(x);
                        x = self.other(e, x);
                    }
                    _ => {
                        end[x as usize] = x;
                    }
                }
            }
            let target = end[x as usize];
            for y in trail.drain(..) {
                end[y as usize] = target;
            }
        }
        end
    }

    /// The critical vertex a V-path from `v` ends at (cones included).
    #[cfg_attr(not(debug_assertions), allow(dead_code))]
    fn path_end(&self, v: u32) -> u32 {
        let mut x = v;
        while let Pairing::Cell(e) = self.vertex_pair[x as usize] {
            x = self.other(e, x);
        }
        x
    }

    /// Cancels every critical vertex that `keep` does not keep with a critical edge, by
    /// reversing the unique V-path between them, taking the persistence pairs of the same
    /// direction (sublevel pairs when descending, superlevel pairs when ascending) in order of
    /// increasing persistence. The Euler characteristic is unchanged; afterwards the critical
    /// real vertices are exactly the kept ones.
    ///
    /// # Errors
    /// A description of the pair that could not be cancelled (no critical edge at its merge
    /// vertex joins its basin to another one): never expected for persistence-chosen sets.
    pub fn simplify(&mut self, pairs: &[super::Pair], keep: &[bool]) -> Result<usize, crate::error::ConstructionError> {
        let mut order: Vec<&super::Pair> = pairs.iter().filter(|p| p.partner.is_some() && !keep[p.extremum]).collect();
        order.sort_by(|a, b| {
            a.persistence
                .total_cmp(&b.persistence)
                .then(self.rank[a.partner.expect("filtered")].cmp(&self.rank[b.partner.expect("filtered")]))
        });
        // Where each vertex's V-path ends, kept up to date without walking the paths again:
        // cancelling (m, s) through the edge (a, b), a flowing to m, sends every vertex that
        // flowed to m on through the reversed path and the edge to b's end, and no other
        // vertex's path changes — so the ends are the basins' initial critical vertices,
        // merged m → end(b) by a union-find.
        let basin = self.initial_path_ends();
        let mut merged: Vec<u32> = (0..basin.len() as u32).collect();
        fn root(merged: &mut [u32], mut x: u32) -> u32 {
            while merged[x as usize] != x {
                merged[x as usize] = merged[merged[x as usize] as usize];
                x = merged[x as usize];
            }
            x
        }
        let mut cancelled = 0;
        let edges_at = self.c.clone();
        for p in order {
            let m = p.extremum as u32;
            let s = p.partner.expect("filtered") as u32;
            if self.vertex_pair[m as usize] != Pairing::Critical {
                return Err(crate::error::ConstructionError::Unfit(format!("vertex {m} is not critical any more")));
            }
            let rs = self.rank[s as usize];
            let mut done = false;
            for &e in &edges_at.vertex_edges[s as usize] {
                if self.edge_pair[e as usize] != Pairing::Critical || self.rank[self.other(e, s) as usize] > rs {
                    continue;
                }
                let [a, b] = self.c.edges[e as usize];
                let ea = root(&mut merged, basin[a as usize]);
                let eb = root(&mut merged, basin[b as usize]);
                debug_assert_eq!((ea, eb), (self.path_end(a), self.path_end(b)));
                let (start, other_end) = match (ea == m, eb == m) {
                    (true, false) => (a, eb),
                    (false, true) => (b, ea),
                    _ => continue,
                };
                self.reverse(e, start);
                merged[m as usize] = other_end;
                cancelled += 1;
                done = true;
                break;
            }
            if !done {
                return Err(crate::error::ConstructionError::Unfit(format!(
                    "no critical edge at vertex {s} joins the basin of extremum {m} to another one (persistence {})",
                    p.persistence
                )));
            }
        }
        Ok(cancelled)
    }

    /// Reverses the V-path from `start` (an endpoint of the critical edge `e`) to its critical
    /// vertex: `e` pairs with `start`, every edge of the path with the vertex after it.
    fn reverse(&mut self, e: u32, start: u32) {
        let mut edge = e;
        let mut x = start;
        loop {
            let next = self.vertex_pair[x as usize];
            self.vertex_pair[x as usize] = Pairing::Cell(edge);
            self.edge_pair[edge as usize] = Pairing::Cell(x);
            match next {
                Pairing::Cell(f) => {
                    edge = f;
                    x = self.other(f, x);
                }
                _ => break,
            }
        }
    }

    /// Critical edges whose both endpoints are real vertices, with their *saddle vertex*: the
    /// endpoint entering the filtration last (the highest when descending, the lowest when
    /// ascending), in whose lower star the edge was made critical.
    pub fn saddles(&self) -> Vec<Saddle> {
        (0..self.c.edges.len())
            .filter(|&e| self.edge_pair[e] == Pairing::Critical)
            .filter_map(|e| {
                let [a, b] = self.c.edges[e];
                if a as usize >= self.c.n_real || b as usize >= self.c.n_real {
                    return None;
                }
                let (top, other) = if self.rank[a as usize] > self.rank[b as usize] { (a, b) } else { (b, a) };
                Some(Saddle { vertex: top as usize, other: other as usize })
            })
            .collect()
    }

    /// The two separatrices of a saddle: the V-paths from the saddle vertex and from the other
    /// endpoint of its edge, each starting at the saddle vertex (real vertices only).
    pub fn separatrices(&self, saddle: &Saddle) -> [Vec<usize>; 2] {
        let own = self.vertex_path(saddle.vertex);
        let mut via = vec![saddle.vertex];
        via.extend(self.vertex_path(saddle.other));
        [own, via]
    }

    /// The V-path from vertex `v` down the gradient (up, when ascending) to a critical
    /// vertex: `v`, then the other end of the edge paired with it, and so on. Real vertices only.
    pub fn vertex_path(&self, v: usize) -> Vec<usize> {
        let mut path = vec![v];
        let mut x = v as u32;
        while let Pairing::Cell(e) = self.vertex_pair[x as usize] {
            x = self.other(e, x);
            path.push(x as usize);
        }
        path.retain(|&w| w < self.c.n_real);
        path
    }
}

/// A critical edge between real vertices, named by its saddle vertex and its other endpoint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Saddle {
    /// The endpoint entering the filtration last (the PL saddle vertex).
    pub vertex: usize,
    /// The other endpoint.
    pub other: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cell {
    Edge(u32),
    Triangle(u32),
}

#[cfg(test)]
mod tests;
