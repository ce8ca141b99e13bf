//! Bindings of the surroundings' distance queries and the clearance kernel. Parts are added
//! in their body's reference frame; queries and the clearance run without the GIL.
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

use ::geometry::{
    clearance, ClearanceError, Control, Cuboid, Cylinder, HalfSpace, Part, RigidMap, Shape, Sphere,
    Surface, TriMesh, V3,
};
use nalgebra::Matrix3;
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyReadonlyArray3, PyReadonlyArray4,
};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::stop::{Poller, StopFlag, INTERRUPTED};

fn rows3(a: &PyReadonlyArray2<'_, f64>, what: &str) -> PyResult<Vec<V3>> {
    let v = a.as_array();
    if v.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "{what} has shape {:?}: must be (M, 3)",
            v.shape()
        )));
    }
    Ok(v.rows()
        .into_iter()
        .map(|r| V3::new(r[0], r[1], r[2]))
        .collect())
}

/// The faces (F, 3) as indices of `n_vertices` vertices (at most 2³²); the error names the
/// first bad face.
pub(crate) fn face_rows(
    faces: &PyReadonlyArray2<'_, i64>,
    n_vertices: usize,
) -> Result<Vec<[u32; 3]>, String> {
    let f = faces.as_array();
    if f.ncols() != 3 {
        return Err(format!("faces have shape {:?}: must be (F, 3)", f.shape()));
    }
    let limit = n_vertices.min(u32::MAX as usize + 1) as u64;
    let mut tris = Vec::with_capacity(f.nrows());
    for (i, r) in f.rows().into_iter().enumerate() {
        let face = [r[0], r[1], r[2]];
        if face.iter().any(|&k| k < 0 || k as u64 >= limit) {
            return Err(format!(
                "face {i} {face:?}: vertex indices must be in 0..{limit}"
            ));
        }
        tris.push(face.map(|k| k as u32));
    }
    Ok(tris)
}

/// The first row of `rows` that is not finite, named (queries of non-finite points have no
/// answer).
fn finite_rows(rows: &[V3], what: &str) -> PyResult<()> {
    match rows.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        None => Ok(()),
        Some(i) => Err(PyValueError::new_err(format!(
            "{what}: row {i} {:?} is not finite; allowed: finite coordinates",
            rows[i].as_slice()
        ))),
    }
}

fn finite(values: &[f64], what: &str) -> PyResult<()> {
    if values.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "{what} must be finite, got {values:?}"
        )))
    }
}

fn positive(x: f64, what: &str) -> PyResult<()> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "{what} must be positive and finite, got {x}"
        )))
    }
}

type ClearanceArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<u32>>);

/// Shapes carried by bodies (index 0, 1, …), in each body's reference frame.
#[pyclass(module = "cablelife._core")]
pub struct Surroundings {
    parts: Vec<Part>,
}

#[pymethods]
impl Surroundings {
    #[new]
    fn new() -> Self {
        Surroundings { parts: vec![] }
    }

    /// Number of parts added.
    fn __len__(&self) -> usize {
        self.parts.len()
    }

    /// Adds a triangle mesh (vertices (V, 3), triangles (F, 3) of vertex indices, merged
    /// vertices, no degenerate triangles); builds its hierarchy. Returns the part index.
    fn add_mesh(
        &mut self,
        py: Python<'_>,
        body: usize,
        vertices: PyReadonlyArray2<'_, f64>,
        faces: PyReadonlyArray2<'_, i64>,
    ) -> PyResult<usize> {
        let v = rows3(&vertices, "vertices")?;
        let tris = face_rows(&faces, v.len()).map_err(PyValueError::new_err)?;
        let mesh = py
            .detach(|| TriMesh::new(&v, &tris))
            .map_err(|e| PyValueError::new_err(e.0))?;
        Ok(self.push(Shape::Mesh(mesh), body))
    }

    /// Adds the half-space below the plane through `point` with outward `normal`.
    fn add_plane(&mut self, body: usize, point: [f64; 3], normal: [f64; 3]) -> PyResult<usize> {
        finite(&point, "plane point")?;
        finite(&normal, "plane normal")?;
        positive(V3::from(normal).norm(), "the length of the plane normal")?;
        let s = HalfSpace::new(V3::from(point), V3::from(normal));
        Ok(self.push(Shape::HalfSpace(s), body))
    }

    /// Adds a box: centre, rotation (3 × 3, columns = box axes), half extents.
    fn add_box(
        &mut self,
        body: usize,
        center: [f64; 3],
        rotation: [[f64; 3]; 3],
        half_extents: [f64; 3],
    ) -> PyResult<usize> {
        finite(&center, "box center")?;
        for h in half_extents {
            positive(h, "box half extent")?;
        }
        let r = Matrix3::from_fn(|i, j| rotation[i][j]);
        let err = (r.transpose() * r - Matrix3::identity()).norm();
        if err.is_nan() || err >= 1e-9 || r.determinant() < 0.0 {
            return Err(PyValueError::new_err(
                "box rotation must be a rotation matrix",
            ));
        }
        let s = Cuboid {
            center: V3::from(center),
            rotation: r,
            half_extents: V3::from(half_extents),
        };
        Ok(self.push(Shape::Cuboid(s), body))
    }

    /// Adds a solid cylinder: centre, axis, radius, half length along the axis.
    fn add_cylinder(
        &mut self,
        body: usize,
        center: [f64; 3],
        axis: [f64; 3],
        radius: f64,
        half_length: f64,
    ) -> PyResult<usize> {
        finite(&center, "cylinder center")?;
        finite(&axis, "cylinder axis")?;
        positive(V3::from(axis).norm(), "the length of the cylinder axis")?;
        positive(radius, "cylinder radius")?;
        positive(half_length, "cylinder half length")?;
        let s = Cylinder::new(V3::from(center), V3::from(axis), radius, half_length);
        Ok(self.push(Shape::Cylinder(s), body))
    }

    /// Adds a solid sphere.
    fn add_sphere(&mut self, body: usize, center: [f64; 3], radius: f64) -> PyResult<usize> {
        finite(&center, "sphere center")?;
        positive(radius, "sphere radius")?;
        let s = Sphere {
            center: V3::from(center),
            radius,
        };
        Ok(self.push(Shape::Sphere(s), body))
    }

    /// Signed distance of points (P, 3) to part `part` (its body frame): dict of
    /// distance (P,), point (P, 3), normal (P, 3).
    fn project_points<'py>(
        &self,
        py: Python<'py>,
        part: usize,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let shape = &self.part(part)?.shape;
        let q = rows3(&points, "points")?;
        finite_rows(&q, "points")?;
        let out: Vec<_> = py.detach(|| {
            use rayon::prelude::*;
            q.par_iter()
                .map(|p| shape.project_point(p, f64::INFINITY, usize::MAX).unwrap())
                .collect()
        });
        let d = out.iter().map(|r| r.distance).collect::<Vec<_>>();
        let flat = |f: &dyn Fn(&::geometry::PointProjection) -> V3| {
            out.iter()
                .flat_map(|r| f(r).iter().copied().collect::<Vec<_>>())
                .collect::<Vec<_>>()
        };
        let dict = PyDict::new(py);
        dict.set_item("distance", PyArray1::from_vec(py, d))?;
        dict.set_item(
            "point",
            PyArray1::from_vec(py, flat(&|r| r.point)).reshape([q.len(), 3])?,
        )?;
        dict.set_item(
            "normal",
            PyArray1::from_vec(py, flat(&|r| r.normal)).reshape([q.len(), 3])?,
        )?;
        Ok(dict)
    }

    /// Closest points of segments [a_i, b_i] ((P, 3) each) and part `part`: dict of
    /// distance (P,) (unsigned), t (P,), on_segment, on_surface, normal (P, 3).
    fn closest_to_segments<'py>(
        &self,
        py: Python<'py>,
        part: usize,
        a: PyReadonlyArray2<'py, f64>,
        b: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let shape = &self.part(part)?.shape;
        let a = rows3(&a, "a")?;
        let b = rows3(&b, "b")?;
        finite_rows(&a, "a")?;
        finite_rows(&b, "b")?;
        if a.len() != b.len() {
            return Err(PyValueError::new_err("a and b must have the same shape"));
        }
        let out: Vec<_> = py.detach(|| {
            use rayon::prelude::*;
            a.par_iter()
                .zip(&b)
                .map(|(p, q)| {
                    shape
                        .closest_to_segment(p, q, f64::INFINITY, usize::MAX)
                        .unwrap()
                })
                .collect()
        });
        let n = a.len();
        let flat = |f: &dyn Fn(&::geometry::SegmentProjection) -> V3| {
            out.iter()
                .flat_map(|r| f(r).iter().copied().collect::<Vec<_>>())
                .collect::<Vec<_>>()
        };
        let dict = PyDict::new(py);
        dict.set_item(
            "distance",
            PyArray1::from_vec(py, out.iter().map(|r| r.distance).collect()),
        )?;
        dict.set_item(
            "t",
            PyArray1::from_vec(py, out.iter().map(|r| r.t).collect()),
        )?;
        dict.set_item(
            "on_segment",
            PyArray1::from_vec(py, flat(&|r| r.on_segment)).reshape([n, 3])?,
        )?;
        dict.set_item(
            "on_surface",
            PyArray1::from_vec(py, flat(&|r| r.on_surface)).reshape([n, 3])?,
        )?;
        dict.set_item(
            "normal",
            PyArray1::from_vec(py, flat(&|r| r.normal)).reshape([n, 3])?,
        )?;
        Ok(dict)
    }

    /// Clearance of a cable of outer `radius` with node positions (T, N, 3) (global);
    /// `to_body` (B, T, 3, 4): per body and step the map [M | v] of global points into the
    /// body's reference frame, X = M x + v. Returns (clearance (T, N) m, part (T, N) index),
    /// or None if it was stopped: by `stop` (a `StopFlag`, read before every step) or by Ctrl-C
    /// when called on the main thread (KeyboardInterrupt is raised again on return).
    /// `progress(done, total)` is called with the steps done every 50 ms.
    #[pyo3(signature = (positions, radius, to_body, progress=None, stop=None))]
    fn clearance<'py>(
        &self,
        py: Python<'py>,
        positions: PyReadonlyArray3<'py, f64>,
        radius: f64,
        to_body: PyReadonlyArray4<'py, f64>,
        progress: Option<Py<PyAny>>,
        stop: Option<Bound<'py, StopFlag>>,
    ) -> PyResult<Option<ClearanceArrays<'py>>> {
        let pos = positions.as_array();
        let (t, n, k) = pos.dim();
        if k != 3 {
            return Err(PyValueError::new_err("positions must have shape (T, N, 3)"));
        }
        positive(radius, "cable radius")?;
        let maps_a = to_body.as_array();
        let (nb, nt, r, c) = maps_a.dim();
        if nt != t || r != 3 || c != 4 {
            return Err(PyValueError::new_err(format!(
                "to_body has shape {:?}: must be (bodies, {t}, 3, 4)",
                maps_a.shape()
            )));
        }
        let points: Vec<V3> = pos
            .outer_iter()
            .flat_map(|step| {
                step.outer_iter()
                    .map(|p| V3::new(p[0], p[1], p[2]))
                    .collect::<Vec<_>>()
            })
            .collect();
        let mut maps = Vec::with_capacity(nb * nt);
        for b in 0..nb {
            for s in 0..nt {
                let m = maps_a.slice(numpy::ndarray::s![b, s, .., ..]);
                maps.push(RigidMap {
                    m: Matrix3::from_fn(|i, j| m[[i, j]]),
                    v: V3::new(m[[0, 3]], m[[1, 3]], m[[2, 3]]),
                });
            }
        }
        if let Some(p) = self.parts.iter().find(|p| p.body >= nb) {
            return Err(PyValueError::new_err(format!(
                "a part is on body {}, but only {nb} body maps are given",
                p.body
            )));
        }
        let parts = &self.parts;
        // The kernel runs in a thread of its own; this one watches it: the stop flag, Ctrl-C
        // (on the main thread) and progress, every 10 ms (Poller: Python every 50 ms).
        // The kernel reads the stop flag itself (a flag set before the call stops it before its
        // first step); Ctrl-C seen here sets it too (or a flag of this call's own).
        let mut poller = Poller::new(stop.as_ref(), progress, t.max(1), t);
        let shared = stop.as_ref().map(|s| s.get().flag());
        let own = AtomicBool::new(false);
        let halt: &AtomicBool = shared.as_deref().unwrap_or(&own);
        let done = AtomicUsize::new(0);
        let control = Control {
            stop: Some(halt),
            done: Some(&done),
        };
        let out = py.detach(|| {
            std::thread::scope(|s| {
                let watcher = std::thread::current();
                let kernel = s.spawn(move || {
                    let out = clearance(parts, &points, n, radius, &maps, control);
                    watcher.unpark(); // done: no need to wait out the watch interval
                    out
                });
                let mut why = None;
                while !kernel.is_finished() {
                    std::thread::park_timeout(Duration::from_millis(10));
                    if why.is_none() {
                        why = poller.poll(done.load(Ordering::Relaxed).min(t));
                        if why.is_some() {
                            halt.store(true, Ordering::Relaxed);
                        }
                    }
                }
                let out = kernel.join();
                if why.is_none() && !halt.load(Ordering::Relaxed) {
                    why = poller.poll(t); // the last progress report: all steps
                }
                (out, why)
            })
        });
        let (out, why) = out;
        // A progress callback that failed (not Ctrl-C) is an error, not an interruption.
        if let Some(why) = why.filter(|w| w != INTERRUPTED) {
            return Err(PyRuntimeError::new_err(why));
        }
        match out {
            Ok(Ok(out)) => Ok(Some((
                PyArray1::from_vec(py, out.value).reshape([t, n])?,
                PyArray1::from_vec(py, out.part).reshape([t, n])?,
            ))),
            Ok(Err(ClearanceError::Stopped)) => {
                py.check_signals()?; // Ctrl-C on the main thread: KeyboardInterrupt now
                Ok(None)
            }
            Ok(Err(ClearanceError::Input(why))) => Err(PyValueError::new_err(why)),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    }
}

impl Surroundings {
    fn push(&mut self, shape: Shape, body: usize) -> usize {
        self.parts.push(Part { shape, body });
        self.parts.len() - 1
    }

    fn part(&self, k: usize) -> PyResult<&Part> {
        self.parts.get(k).ok_or_else(|| {
            PyValueError::new_err(format!(
                "part {k} does not exist ({} parts)",
                self.parts.len()
            ))
        })
    }
}

/// Merged vertices (M, 3) and re-indexed faces (F, 3).
type Welded<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>);

/// Closedness, boundary edges and shells of a mesh (`faces` (F, 3) indices below
/// `n_vertices`): (watertight, boundary edge count, shell per face (F,), number of shells).
#[pyfunction]
fn mesh_topology<'py>(
    py: Python<'py>,
    faces: PyReadonlyArray2<'py, i64>,
    n_vertices: usize,
) -> PyResult<(bool, usize, Bound<'py, PyArray1<i64>>, usize)> {
    let tri = face_rows(&faces, n_vertices).map_err(PyValueError::new_err)?;
    let t = py.detach(|| ::geometry::topology(n_vertices, &tri));
    let shell = PyArray1::from_vec(py, t.shell.into_iter().map(i64::from).collect());
    Ok((t.watertight, t.boundary, shell, t.shells))
}

/// Merges the vertices (N, 3) of a triangle soup that agree to 8 decimals (first appearance's
/// order and coordinates kept) and re-indexes the faces (F, 3): (vertices (M, 3), faces (F, 3)).
#[pyfunction]
fn weld_vertices<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
) -> PyResult<Welded<'py>> {
    let v = vertices.as_array();
    let f = faces.as_array();
    if v.ncols() != 3 || f.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "vertices {:?} and faces {:?}: must be (N, 3) and (F, 3)",
            v.shape(),
            f.shape()
        )));
    }
    let v: Vec<[f64; 3]> = v.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
    let mut f: Vec<[i64; 3]> = f.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
    let merged = py
        .detach(|| ::geometry::weld_vertices(&v, &mut f))
        .map_err(PyValueError::new_err)?;
    let (m, n) = (merged.len(), f.len());
    let merged = PyArray1::from_vec(py, merged.into_iter().flatten().collect()).reshape([m, 3])?;
    let faces = PyArray1::from_vec(py, f.into_iter().flatten().collect()).reshape([n, 3])?;
    Ok((merged, faces))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Surroundings>()?;
    m.add_function(wrap_pyfunction!(weld_vertices, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_topology, m)?)?;
    Ok(())
}
