//! Maximum flow on a network with real capacities (Dinic's blocking flows, iterative, so a
//! path may run through a whole volume without recursion): the active-set iteration's
//! multipliers where a cluster's tight rows close cycles, and its minimum cut where they
//! cannot be non-negative.
//!
//! petgraph's `ford_fulkerson` augments one shortest path per search; on the active set's
//! networks (10⁵ nodes, paths hundreds of arcs long) Dinic's phases are what keeps one outer
//! iteration cheap next to its conjugate gradients.

/// A directed network; each arc is stored with its reverse (arc `a ^ 1`).
pub(super) struct Network {
    first: Vec<u32>,
    next: Vec<u32>,
    to: Vec<u32>,
    residual: Vec<f64>,
    /// Each node's level in the current phase (END outside it), and its current arc: kept
    /// between calls so that a flow through one small component of a large network touches
    /// that component only.
    level: Vec<u32>,
    current: Vec<u32>,
}

const END: u32 = u32::MAX;

impl Network {
    pub(super) fn new(nodes: usize) -> Network {
        Network {
            first: vec![END; nodes],
            next: Vec::new(),
            to: Vec::new(),
            residual: Vec::new(),
            level: vec![END; nodes],
            current: vec![END; nodes],
        }
    }

    pub(super) fn nodes(&self) -> usize {
        self.first.len()
    }

    pub(super) fn add_node(&mut self) -> usize {
        self.first.push(END);
        self.level.push(END);
        self.current.push(END);
        self.first.len() - 1
    }

    /// An arc `u → v` of capacity `cap` (may be infinite); returns its index for [`Self::flow`].
    pub(super) fn add_arc(&mut self, u: usize, v: usize, cap: f64) -> usize {
        let a = self.to.len();
        for (from, into, c) in [(u, v, cap), (v, u, 0.0)] {
            self.to.push(into as u32);
            self.residual.push(c);
            self.next.push(self.first[from]);
            self.first[from] = self.to.len() as u32 - 1;
        }
        a
    }

    /// The flow on arc `a` (its reverse's residual).
    pub(super) fn flow(&self, a: usize) -> f64 {
        self.residual[a ^ 1]
    }

    /// Levels by breadth-first search from `s` over the nodes it reaches (listed in `queue`;
    /// every other node stays at END); true when `t` is among them.
    fn levels(&mut self, s: usize, t: usize, eps: f64, queue: &mut Vec<usize>) -> bool {
        for &u in queue.iter() {
            self.level[u] = END;
        }
        self.level[s] = 0;
        self.current[s] = self.first[s];
        queue.clear();
        queue.push(s);
        let mut head = 0;
        while head < queue.len() {
            let u = queue[head];
            // no shortest path runs through a node at t's level or beyond: stop there
            if self.level[t] != END && self.level[u] >= self.level[t] {
                break;
            }
            head += 1;
            let mut a = self.first[u];
            while a != END {
                let v = self.to[a as usize] as usize;
                if self.level[v] == END && self.residual[a as usize] > eps {
                    self.level[v] = self.level[u] + 1;
                    self.current[v] = self.first[v];
                    queue.push(v);
                }
                a = self.next[a as usize];
            }
        }
        self.level[t] != END
    }

    /// Pushes the maximum flow from `s` to `t`, ignoring residuals at or below `eps`; returns
    /// its value. The work is within the nodes `s` reaches.
    pub(super) fn max_flow(&mut self, s: usize, t: usize, eps: f64) -> f64 {
        let mut queue = Vec::new();
        let mut path: Vec<u32> = Vec::new();
        let mut total = 0.0;
        while self.levels(s, t, eps, &mut queue) {
            path.clear();
            let mut u = s;
            loop {
                if u == t {
                    // augment by the bottleneck, retreat to the first arc it saturates
                    let push = path.iter().map(|&a| self.residual[a as usize]).fold(f64::INFINITY, f64::min);
                    let mut cut = path.len();
                    for (k, &a) in path.iter().enumerate() {
                        self.residual[a as usize] -= push;
                        self.residual[(a ^ 1) as usize] += push;
                        if cut == path.len() && self.residual[a as usize] <= eps {
                            cut = k;
                        }
                    }
                    total += push;
                    path.truncate(cut);
                    u = path.last().map_or(s, |&a| self.to[a as usize] as usize);
                    continue;
                }
                // advance along the current arc of u, or retreat when u has none left
                let mut a = self.current[u];
                while a != END {
                    let v = self.to[a as usize] as usize;
                    if self.residual[a as usize] > eps && self.level[v] == self.level[u] + 1 {
                        break;
                    }
                    a = self.next[a as usize];
                }
                self.current[u] = a;
                if a != END {
                    path.push(a);
                    u = self.to[a as usize] as usize;
                    continue;
                }
                // dead end: no node at u's level reaches t through it any more
                self.level[u] = END;
                match path.pop() {
                    Some(back) => {
                        u = self.to[(back ^ 1) as usize] as usize;
                        self.current[u] = self.next[self.current[u] as usize];
                    }
                    None => break,
                }
            }
        }
        for &u in &queue {
            self.level[u] = END;
        }
        total
    }

    /// Marks in `seen` the nodes reachable from `s` through residuals above `eps` (after
    /// [`Self::max_flow`]: the source side of a minimum cut).
    pub(super) fn mark_reachable(&self, s: usize, eps: f64, seen: &mut [bool]) {
        seen[s] = true;
        let mut stack = vec![s];
        while let Some(u) = stack.pop() {
            let mut a = self.first[u];
            while a != END {
                let v = self.to[a as usize] as usize;
                if !seen[v] && self.residual[a as usize] > eps {
                    seen[v] = true;
                    stack.push(v);
                }
                a = self.next[a as usize];
            }
        }
    }

    /// The nodes reachable from `s` (see [`Self::mark_reachable`]).
    #[cfg(test)]
    pub(super) fn reachable(&self, s: usize, eps: f64) -> Vec<bool> {
        let mut seen = vec![false; self.first.len()];
        self.mark_reachable(s, eps, &mut seen);
        seen
    }
}

#[cfg(test)]
mod tests {
    use super::Network;

    #[test]
    fn the_maximum_flow_equals_the_minimum_cut() {
        // s=0, t=5; the classic CLRS network (max flow 23)
        let arcs = [
            (0, 1, 16.0),
            (0, 2, 13.0),
            (2, 1, 4.0),
            (1, 3, 12.0),
            (3, 2, 9.0),
            (2, 4, 14.0),
            (4, 3, 7.0),
            (3, 5, 20.0),
            (4, 5, 4.0),
        ];
        let mut net = Network::new(6);
        let ids: Vec<usize> = arcs.iter().map(|&(u, v, c)| net.add_arc(u, v, c)).collect();
        let value = net.max_flow(0, 5, 1e-12);
        assert!((value - 23.0).abs() < 1e-12, "{value}");
        let side = net.reachable(0, 1e-12);
        assert!(side[0] && !side[5]);
        let cut: f64 = arcs.iter().filter(|&&(u, v, _)| side[u] && !side[v]).map(|a| a.2).sum();
        assert!((cut - value).abs() < 1e-12, "cut {cut}");
        // conservation at every inner node, capacities respected
        for node in 1..5 {
            let net_out: f64 = arcs
                .iter()
                .zip(&ids)
                .map(|(&(u, v, _), &a)| {
                    if u == node {
                        net.flow(a)
                    } else if v == node {
                        -net.flow(a)
                    } else {
                        0.0
                    }
                })
                .sum();
            assert!(net_out.abs() < 1e-12, "node {node}: {net_out}");
        }
        for (&(_, _, c), &a) in arcs.iter().zip(&ids) {
            assert!((0.0..=c + 1e-12).contains(&net.flow(a)));
        }
    }

    #[test]
    fn flows_in_separate_components_stay_in_them() {
        // component A: 0 → 2 → 1 (cap 3, then 5); component B: 3 → 4 → 5 (cap 7, then 2)
        let mut net = Network::new(6);
        let a_in = net.add_arc(0, 2, 3.0);
        net.add_arc(2, 1, 5.0);
        let b_in = net.add_arc(3, 4, 7.0);
        let b_out = net.add_arc(4, 5, 2.0);
        assert_eq!(net.max_flow(0, 1, 1e-12), 3.0);
        assert_eq!(net.flow(b_in), 0.0);
        assert_eq!(net.max_flow(3, 5, 1e-12), 2.0);
        assert_eq!((net.flow(a_in), net.flow(b_out)), (3.0, 2.0));
        let mut side = vec![false; net.nodes()];
        net.mark_reachable(0, 1e-12, &mut side);
        net.mark_reachable(3, 1e-12, &mut side);
        assert_eq!(side, [true, false, false, true, true, false]);
    }

    #[test]
    fn infinite_arcs_and_a_long_chain_need_no_recursion() {
        // s → 1 → 2 → … → n−2 → t: infinite inner arcs, finite ends
        let n = 200_000;
        let mut net = Network::new(n);
        let first = net.add_arc(0, 1, 2.5);
        for v in 1..n - 2 {
            net.add_arc(v, v + 1, f64::INFINITY);
        }
        net.add_arc(n - 2, n - 1, 4.0);
        assert_eq!(net.max_flow(0, n - 1, 1e-12), 2.5);
        assert_eq!(net.flow(first), 2.5);
        assert!(!net.reachable(0, 1e-12)[1]);
    }
}
