//! Triangle meshes as obstacles: the signed distance of a point and the outward normal, from
//! the closest point over the triangles (found through a bounding-volume hierarchy of
//! axis-aligned boxes) and the sign of the angle-weighted pseudo-normal of the closest feature
//! (face, edge or vertex), which is exact for a closed, consistently oriented mesh (Bærentzen
//! and Aanæs, "Signed distance computation using the angle weighted pseudonormal", 2005).
//! Outside a convex mesh the distance is continuously differentiable and its gradient is the
//! returned normal, so the contact Newton solve sees a smooth gap.

use std::collections::HashMap;

use nalgebra::Vector3;

use crate::error::{Error, Result};

/// Most triangles in a leaf of the hierarchy.
const LEAF: usize = 4;

/// A triangle mesh (world frame, m): vertices, faces (counter-clockwise seen from outside),
/// and what the distance query needs (normals, pseudo-normals, the hierarchy).
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleMesh {
    vertices: Vec<Vector3<f64>>,
    faces: Vec<[usize; 3]>,
    face_normal: Vec<Vector3<f64>>,
    vertex_normal: Vec<Vector3<f64>>,
    /// Per face, the pseudo-normal of its edges (v0v1, v1v2, v2v0).
    edge_normal: Vec<[Vector3<f64>; 3]>,
    nodes: Vec<Node>,
    /// Face indices in the order of the leaves.
    order: Vec<usize>,
}

/// A node of the hierarchy: its box and either two children or a range of `order`.
#[derive(Debug, Clone, PartialEq)]
struct Node {
    lo: Vector3<f64>,
    hi: Vector3<f64>,
    kind: Kind,
}

#[derive(Debug, Clone, PartialEq)]
enum Kind {
    Inner(usize, usize),
    Leaf(usize, usize),
}

/// The closest feature of a triangle: the face, edge `k` (from vertex `k` to `k + 1`), or
/// vertex `k`.
#[derive(Debug, Clone, Copy)]
enum Feature {
    Face,
    Edge(usize),
    Vertex(usize),
}

/// The closest point of the triangle `(a, b, c)` to `p`, and its feature.
fn closest_on_triangle(
    p: &Vector3<f64>,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    c: &Vector3<f64>,
) -> (Vector3<f64>, Feature) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (*a, Feature::Vertex(0));
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (*b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, Feature::Edge(0));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (*c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, Feature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w, Feature::Face)
}

/// Squared distance of `p` to the box `[lo, hi]`.
fn box_distance2(p: &Vector3<f64>, lo: &Vector3<f64>, hi: &Vector3<f64>) -> f64 {
    (0..3)
        .map(|k| {
            let d = (lo[k] - p[k]).max(0.0).max(p[k] - hi[k]);
            d * d
        })
        .sum()
}

impl TriangleMesh {
    /// A mesh from its vertices (m, world) and faces (indices into `vertices`, counter-clockwise
    /// seen from outside: the outward normal is `(v1 - v0) × (v2 - v0)`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `vertices[i]` (not finite), `faces[i]` (an index out
    /// of range, or a degenerate triangle of zero area), or `faces` (empty).
    pub fn new(vertices: Vec<[f64; 3]>, faces: Vec<[usize; 3]>) -> Result<Self> {
        let vertices: Vec<Vector3<f64>> = vertices
            .iter()
            .enumerate()
            .map(|(i, v)| {
                if v.iter().all(|x| x.is_finite()) {
                    Ok(Vector3::from(*v))
                } else {
                    Err(Error::invalid(
                        format!("vertices[{i}]"),
                        format!("{v:?}"),
                        "finite coordinates (m)",
                    ))
                }
            })
            .collect::<Result<_>>()?;
        if faces.is_empty() {
            return Err(Error::invalid("faces", "[]", "at least one triangle"));
        }
        let mut face_normal = Vec::with_capacity(faces.len());
        for (i, f) in faces.iter().enumerate() {
            if f.iter().any(|&k| k >= vertices.len()) {
                return Err(Error::invalid(
                    format!("faces[{i}]"),
                    format!("{f:?}"),
                    format!("indices below the {} vertices", vertices.len()),
                ));
            }
            let (a, b, c) = (vertices[f[0]], vertices[f[1]], vertices[f[2]]);
            let n = (b - a).cross(&(c - a));
            let l = n.norm();
            if !(l > 0.0 && l.is_finite()) {
                return Err(Error::invalid(
                    format!("faces[{i}]"),
                    format!("{f:?}"),
                    "a triangle of non-zero area",
                ));
            }
            face_normal.push(n / l);
        }
        // Angle-weighted vertex pseudo-normals, edge pseudo-normals (sum of the adjacent
        // faces' normals).
        let mut vertex_normal = vec![Vector3::zeros(); vertices.len()];
        let mut edges: HashMap<(usize, usize), Vector3<f64>> = HashMap::new();
        for (f, n) in faces.iter().zip(&face_normal) {
            for k in 0..3 {
                let (i, j, l) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
                let (u, w) = (vertices[j] - vertices[i], vertices[l] - vertices[i]);
                let angle = u.angle(&w);
                vertex_normal[i] += n * angle;
                *edges
                    .entry((i.min(j), i.max(j)))
                    .or_insert_with(Vector3::zeros) += n;
            }
        }
        let unit = |v: Vector3<f64>| v.try_normalize(0.0).unwrap_or(v);
        let vertex_normal = vertex_normal.into_iter().map(unit).collect();
        let edge_normal = faces
            .iter()
            .map(|f| {
                std::array::from_fn(|k| {
                    let (i, j) = (f[k], f[(k + 1) % 3]);
                    unit(edges[&(i.min(j), i.max(j))])
                })
            })
            .collect();
        let mut mesh = Self {
            vertices,
            faces,
            face_normal,
            vertex_normal,
            edge_normal,
            nodes: Vec::new(),
            order: Vec::new(),
        };
        mesh.order = (0..mesh.faces.len()).collect();
        let n = mesh.order.len();
        mesh.build(0, n);
        Ok(mesh)
    }

    /// The vertices (m, world).
    pub fn vertices(&self) -> Vec<[f64; 3]> {
        self.vertices.iter().map(|v| [v.x, v.y, v.z]).collect()
    }

    /// The faces (vertex indices).
    pub fn faces(&self) -> &[[usize; 3]] {
        &self.faces
    }

    fn centroid(&self, f: usize) -> Vector3<f64> {
        let t = self.faces[f];
        (self.vertices[t[0]] + self.vertices[t[1]] + self.vertices[t[2]]) / 3.0
    }

    /// Builds the node of `order[start..end]` (median split along the box's longest axis);
    /// returns its index.
    fn build(&mut self, start: usize, end: usize) -> usize {
        let (mut lo, mut hi) = (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(-f64::INFINITY),
        );
        for &f in &self.order[start..end] {
            for &v in &self.faces[f] {
                lo = lo.inf(&self.vertices[v]);
                hi = hi.sup(&self.vertices[v]);
            }
        }
        let index = self.nodes.len();
        self.nodes.push(Node {
            lo,
            hi,
            kind: Kind::Leaf(start, end),
        });
        if end - start > LEAF {
            let axis = (hi - lo).imax();
            let mut part = self.order[start..end].to_vec();
            part.sort_by(|a, b| self.centroid(*a)[axis].total_cmp(&self.centroid(*b)[axis]));
            self.order[start..end].copy_from_slice(&part);
            let mid = start + (end - start) / 2;
            let left = self.build(start, mid);
            let right = self.build(mid, end);
            self.nodes[index].kind = Kind::Inner(left, right);
        }
        index
    }

    /// The signed distance of `x` (m; negative inside) and the outward unit normal there
    /// (the direction from the closest point of the mesh to `x`, outward).
    pub fn distance(&self, x: &Vector3<f64>) -> (f64, Vector3<f64>) {
        let mut best = (f64::INFINITY, Vector3::zeros(), Vector3::zeros());
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i];
            if box_distance2(x, &node.lo, &node.hi) >= best.0 {
                continue;
            }
            match node.kind {
                Kind::Inner(a, b) => {
                    let da = box_distance2(x, &self.nodes[a].lo, &self.nodes[a].hi);
                    let db = box_distance2(x, &self.nodes[b].lo, &self.nodes[b].hi);
                    // The nearer child last, so that it is searched first.
                    if da < db {
                        stack.extend([b, a]);
                    } else {
                        stack.extend([a, b]);
                    }
                }
                Kind::Leaf(s, e) => {
                    for &f in &self.order[s..e] {
                        let t = self.faces[f];
                        let (a, b, c) = (
                            &self.vertices[t[0]],
                            &self.vertices[t[1]],
                            &self.vertices[t[2]],
                        );
                        let (q, feature) = closest_on_triangle(x, a, b, c);
                        let d2 = (x - q).norm_squared();
                        if d2 < best.0 {
                            let pseudo = match feature {
                                Feature::Face => self.face_normal[f],
                                Feature::Edge(k) => self.edge_normal[f][k],
                                Feature::Vertex(k) => self.vertex_normal[t[k]],
                            };
                            best = (d2, q, pseudo);
                        }
                    }
                }
            }
        }
        let (d2, q, pseudo) = best;
        let d = d2.sqrt();
        let v = x - q;
        let sign = if v.dot(&pseudo) < 0.0 { -1.0 } else { 1.0 };
        if d > 1e-14 * (1.0 + x.norm()) {
            (sign * d, v * (sign / d))
        } else {
            (0.0, pseudo)
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// The unit cube's 12 triangles, outward.
    fn cube() -> TriangleMesh {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let f = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        TriangleMesh::new(v, f).unwrap()
    }

    #[test]
    fn cube_distance_is_the_box_distance() {
        let m = cube();
        // The exact distance to the unit box, inside and out.
        let exact = |p: Vector3<f64>| {
            let q = p.map(|x| (x - 0.5).abs() - 0.5);
            let out = q.map(|x| x.max(0.0)).norm();
            out + q.max().min(0.0)
        };
        let mut worst: f64 = 0.0;
        for i in 0..7 {
            for j in 0..7 {
                for k in 0..7 {
                    let p =
                        Vector3::new(i as f64, j as f64, k as f64) * 0.37 - Vector3::repeat(0.6);
                    let (d, n) = m.distance(&p);
                    worst = worst.max((d - exact(p)).abs());
                    let h = 1e-7;
                    // Outside the convex mesh the distance is differentiable (inside, not on
                    // its medial axis).
                    if d > 1e-3 {
                        for a in 0..3 {
                            let mut e = Vector3::zeros();
                            e[a] = h;
                            let g = (m.distance(&(p + e)).0 - m.distance(&(p - e)).0) / (2.0 * h);
                            assert!((g - n[a]).abs() < 1e-6, "{p:?}: {g} vs {}", n[a]);
                        }
                    }
                }
            }
        }
        assert!(worst < 1e-14, "{worst:e}");
    }

    #[test]
    fn bad_meshes_are_named_errors() {
        let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let e = TriangleMesh::new(v.clone(), vec![[0, 1, 3]]).unwrap_err();
        assert!(e.to_string().contains("faces[0]"), "{e}");
        let e = TriangleMesh::new(v.clone(), vec![[0, 1, 1]]).unwrap_err();
        assert!(e.to_string().contains("faces[0]"), "{e}");
        let e = TriangleMesh::new(v, vec![]).unwrap_err();
        assert!(e.to_string().contains("faces"), "{e}");
        let e = TriangleMesh::new(vec![[f64::NAN, 0.0, 0.0]], vec![[0, 0, 0]]).unwrap_err();
        assert!(e.to_string().contains("vertices[0]"), "{e}");
    }
}
