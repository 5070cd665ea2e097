//! A flattened bounding volume hierarchy: nodes in depth-first order, the
//! first child right after its parent, traversed front to back.

use super::sah::{self, BuildItem, BuildNode};
use crate::math::{Aabb, Ray};

/// 64 bytes: bounds, then either the first primitive (leaf) or the second child.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    /// Leaf: index of the first primitive. Interior: index of the second child.
    offset: u32,
    /// Number of primitives; zero for interior nodes.
    count: u16,
    /// Split axis of an interior node, to visit the nearer child first.
    axis: u8,
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
}

impl Bvh {
    /// Builds over the given primitive bounds. Returns the tree and the order
    /// in which the caller must store its primitives (leaves index into it).
    pub fn build(bounds: &[Aabb]) -> (Self, Vec<u32>) {
        if bounds.is_empty() {
            return (Self::default(), Vec::new());
        }
        let mut items: Vec<BuildItem> = bounds
            .iter()
            .enumerate()
            .map(|(i, b)| BuildItem {
                bounds: *b,
                centroid: b.centroid(),
                index: i as u32,
            })
            .collect();
        let root = sah::build(&mut items, 0);
        let mut nodes = Vec::with_capacity(root.node_count());
        flatten(&root, &mut nodes);
        (Self { nodes }, items.iter().map(|i| i.index).collect())
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    /// Nearest hit. `hit_primitive(index, t_max)` tests one primitive and
    /// returns its hit distance if it is nearer than `t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, mut t_max: f64, mut hit_primitive: impl FnMut(usize, f64) -> Option<f64>) -> Option<f64> {
        let mut nearest = None;
        self.traverse(ray, &mut t_max, |index, t_max| {
            if let Some(t) = hit_primitive(index, *t_max) {
                *t_max = t;
                nearest = Some(t);
            }
            false
        });
        nearest
    }

    /// Whether any primitive is hit before `t_max`; stops at the first hit.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f64, mut hit_primitive: impl FnMut(usize, f64) -> bool) -> bool {
        let mut t = t_max;
        let mut found = false;
        self.traverse(ray, &mut t, |index, t_max| {
            found = hit_primitive(index, *t_max);
            found
        });
        found
    }

    /// Front-to-back traversal; `visit` returns true to stop early.
    #[inline]
    fn traverse(&self, ray: &Ray, t_max: &mut f64, mut visit: impl FnMut(usize, &mut f64) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let inverse_direction = glam::DVec3::ONE / ray.direction;
        let negative = [
            inverse_direction.x < 0.0,
            inverse_direction.y < 0.0,
            inverse_direction.z < 0.0,
        ];
        let mut stack = [0u32; 64];
        let mut stack_len = 0;
        let mut current = 0usize;
        loop {
            let node = &self.nodes[current];
            if node.bounds.hit_distance(ray.origin, inverse_direction, *t_max).is_some() {
                if node.count > 0 {
                    let first = node.offset as usize;
                    for index in first..first + node.count as usize {
                        if visit(index, t_max) {
                            return;
                        }
                    }
                } else {
                    // Visit the child on the ray's near side first.
                    let (near, far) = if negative[node.axis as usize] {
                        (node.offset as usize, current + 1)
                    } else {
                        (current + 1, node.offset as usize)
                    };
                    stack[stack_len] = far as u32;
                    stack_len += 1;
                    current = near;
                    continue;
                }
            }
            if stack_len == 0 {
                return;
            }
            stack_len -= 1;
            current = stack[stack_len] as usize;
        }
    }
}

fn flatten(node: &BuildNode, nodes: &mut Vec<Node>) {
    match node {
        BuildNode::Leaf { bounds, first, count } => nodes.push(Node {
            bounds: *bounds,
            offset: *first as u32,
            count: *count as u16,
            axis: 0,
        }),
        BuildNode::Interior {
            bounds, axis, children, ..
        } => {
            let index = nodes.len();
            nodes.push(Node {
                bounds: *bounds,
                offset: 0,
                count: 0,
                axis: *axis as u8,
            });
            flatten(&children[0], nodes);
            nodes[index].offset = nodes.len() as u32;
            flatten(&children[1], nodes);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Random boxes; the BVH's nearest hit must equal brute force's.
    #[test]
    fn matches_brute_force_on_random_boxes() {
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let boxes: Vec<Aabb> = (0..2000)
            .map(|_| {
                let c = DVec3::new(next(), next(), next()) * 100.0;
                let e = DVec3::new(next(), next(), next()) * 2.0;
                Aabb::new(c - e, c + e)
            })
            .collect();
        let (bvh, order) = Bvh::build(&boxes);
        let mut sorted_order = order.clone();
        sorted_order.sort_unstable();
        assert_eq!(sorted_order, (0..boxes.len() as u32).collect::<Vec<_>>());
        for _ in 0..2000 {
            let o = DVec3::new(next(), next(), next()) * 120.0 - DVec3::splat(10.0);
            let d = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            let ray = Ray::new(o, d);
            let inv = DVec3::ONE / ray.direction;
            let brute = boxes
                .iter()
                .filter_map(|b| b.hit_distance(ray.origin, inv, f64::INFINITY))
                .fold(f64::INFINITY, f64::min);
            let fast = bvh
                .intersect(&ray, f64::INFINITY, |i, t_max| {
                    boxes[order[i] as usize].hit_distance(ray.origin, inv, t_max)
                })
                .unwrap_or(f64::INFINITY);
            assert_eq!(brute, fast);
            let blocked = bvh.occluded(&ray, f64::INFINITY, |i, t_max| {
                boxes[order[i] as usize].hit_distance(ray.origin, inv, t_max).is_some()
            });
            assert_eq!(blocked, brute.is_finite());
        }
    }
}
