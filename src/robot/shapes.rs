//! The links' collision shapes: for each collision mesh of an arm's link, the tighter of
//! the capsule along the mesh's main axis and the box on its principal axes, each holding
//! every vertex by construction, in the link's frame, with the ball around it for a quick
//! first test — or, for a bent link where they are much tighter, up to three boxes stacked
//! along one of the mesh's axes that together hold it (`slabs.rs`); for each mesh of a link that
//! stays with the root (the torso), such stacked boxes.
//!
//! A configuration whose shapes are apart is one whose meshes are apart. Capsules and
//! boxes rather than convex hulls: parry3d 0.25's hulls of the YuMi's coarse meshes answer
//! point and contact queries wrongly (a vertex of the mesh reported a centimetre outside
//! its own hull), and a capsule's or a box's queries are exact. The price is a fatter arm.

use std::path::Path;

use std::f32::consts::FRAC_PI_2;

use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use parry3d::shape::SharedShape;

use super::RobotError;
use super::chain::Chain;
use super::slabs::{MAX_ARM_BOXES, MAX_BOXES, stacked_boxes};
use super::urdf::{Element, Geometry, Model};

/// One link's collision shape, in the link's frame.
#[derive(Clone)]
pub struct LinkShape {
    /// Index into [`Model::links`].
    pub link: usize,
    pub name: String,
    /// The shape's placement in the link's frame.
    pub local: Isometry3<f32>,
    pub shape: SharedShape,
    /// A ball around the shape (in the shape's frame, `local`) for the first test.
    pub center: Point3<f32>,
    pub radius: f32,
}

impl std::fmt::Debug for LinkShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LinkShape")
            .field("name", &self.name)
            .field("radius", &self.radius)
            .finish_non_exhaustive()
    }
}

/// The collision shapes of a robot: those fixed to the root (the torso) and, per arm, those
/// each link of [`Chain::carried`] has (`arms[a][i]` belongs to `carried[i]` of arm `a`).
#[derive(Debug, Clone)]
pub struct RobotShapes {
    pub torso: Vec<LinkShape>,
    /// Per arm, per carried link, its shapes.
    pub arms: Vec<Vec<Vec<LinkShape>>>,
}

impl RobotShapes {
    /// The collision elements of every link, made convex.
    pub fn new(model: &Model, arms: &[Chain]) -> Result<RobotShapes, RobotError> {
        let shapes_of = |link: usize| -> Result<Vec<LinkShape>, RobotError> {
            let mut shapes = Vec::new();
            for element in &model.links[link].collisions {
                shapes.extend(moving_link_shapes(model, link, element)?);
            }
            Ok(shapes)
        };
        let carried: Vec<usize> = arms
            .iter()
            .flat_map(|a| a.carried.iter().map(|c| c.link))
            .collect();
        // What stays with the root is big and still: boxes stacked along it hold its
        // mesh far more tightly than one shape around all of it.
        let mut torso = Vec::new();
        for link in 0..model.links.len() {
            if carried.contains(&link) {
                continue;
            }
            for element in &model.links[link].collisions {
                torso.extend(still_link_shapes(model, link, element)?);
            }
        }
        let arms = arms
            .iter()
            .map(|a| a.carried.iter().map(|c| shapes_of(c.link)).collect())
            .collect::<Result<_, _>>()?;
        Ok(RobotShapes { torso, arms })
    }
}

fn link_shape(model: &Model, link: usize, element: &Element) -> Result<LinkShape, RobotError> {
    let name = model.links[link].name.clone();
    let bad = |message: String| RobotError::Urdf {
        file: model.file.clone(),
        message: format!("link \"{name}\": {message}"),
    };
    let mut local = element.origin.cast::<f32>();
    let shape = match &element.geometry {
        Geometry::Mesh { path, scale } => {
            let s = scale.cast::<f32>();
            let points: Vec<Point3<f32>> = read_stl(path)?
                .into_iter()
                .map(|p| Point3::from(p.coords.component_mul(&s)))
                .collect();
            let (placed, shape) = hull_around(&points)
                .ok_or_else(|| bad(format!("mesh {} has no vertices", path.display())))?;
            local *= placed;
            shape
        }
        Geometry::Box { size } => SharedShape::cuboid(
            size.x as f32 / 2.0,
            size.y as f32 / 2.0,
            size.z as f32 / 2.0,
        ),
        Geometry::Sphere { radius } => SharedShape::ball(*radius as f32),
        Geometry::Cylinder { radius, length } => {
            // parry's cylinder stands along y, URDF's along z.
            local *= UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2);
            SharedShape::cylinder(*length as f32 / 2.0, *radius as f32)
        }
        Geometry::Capsule { radius, length } => {
            SharedShape::capsule_z(*length as f32 / 2.0, *radius as f32)
        }
    };
    let aabb = shape.compute_local_aabb();
    Ok(LinkShape {
        link,
        name,
        local,
        shape,
        center: aabb.center(),
        radius: aabb.half_extents().norm(),
    })
}

/// Stacked boxes are an arm link's shapes when together they take at most this fraction
/// of the volume of the one capsule or box around its mesh: the YuMi's links are bent, and
/// one shape around a bend fills the space beside it (the shoulders' boxes overlapped the
/// other arm's in configurations where the meshes are centimetres apart).
const STACK_WHEN_TIGHTER: f32 = 0.75;

/// The shapes of a link an arm moves: the capsule or box around its mesh, or up to
/// [`MAX_ARM_BOXES`] boxes stacked along one of the mesh's axes (`slabs.rs`) when they are
/// much tighter; any other
/// geometry as [`link_shape`] makes it.
fn moving_link_shapes(
    model: &Model,
    link: usize,
    element: &Element,
) -> Result<Vec<LinkShape>, RobotError> {
    let single = link_shape(model, link, element)?;
    if !matches!(element.geometry, Geometry::Mesh { .. }) {
        return Ok(vec![single]);
    }
    let stacked = stacked_link_shapes(model, link, element, MAX_ARM_BOXES)?;
    let volume = |shapes: &[LinkShape]| -> f32 {
        shapes
            .iter()
            .map(|s| s.shape.mass_properties(1.0).mass())
            .sum()
    };
    Ok(
        if volume(&stacked) <= STACK_WHEN_TIGHTER * volume(std::slice::from_ref(&single)) {
            stacked
        } else {
            vec![single]
        },
    )
}

/// The shapes of a link that does not move with an arm: a mesh as boxes stacked along one
/// of its axes (`slabs.rs`), any other geometry as [`link_shape`] makes it.
fn still_link_shapes(
    model: &Model,
    link: usize,
    element: &Element,
) -> Result<Vec<LinkShape>, RobotError> {
    stacked_link_shapes(model, link, element, MAX_BOXES)
}

/// A mesh as at most `max_boxes` boxes stacked along one of its axes (`slabs.rs`), any
/// other geometry as [`link_shape`] makes it.
fn stacked_link_shapes(
    model: &Model,
    link: usize,
    element: &Element,
    max_boxes: usize,
) -> Result<Vec<LinkShape>, RobotError> {
    let Geometry::Mesh { path, scale } = &element.geometry else {
        return Ok(vec![link_shape(model, link, element)?]);
    };
    let s = scale.cast::<f32>();
    let triangles: Vec<[Point3<f32>; 3]> = read_stl_triangles(path)?
        .into_iter()
        .map(|t| t.map(|p| Point3::from(p.coords.component_mul(&s))))
        .collect();
    let name = model.links[link].name.clone();
    let origin = element.origin.cast::<f32>();
    let boxes = stacked_boxes(&triangles, max_boxes);
    if boxes.is_empty() {
        return Err(RobotError::Urdf {
            file: model.file.clone(),
            message: format!("link \"{name}\": mesh {} has no vertices", path.display()),
        });
    }
    Ok(boxes
        .iter()
        .map(|b| {
            // A hair more, so that rounding in the queries never leaves a vertex out.
            let half = (b.maxs - b.mins) / 2.0 * 1.0001 + Vector3::repeat(1e-6);
            let shape = SharedShape::cuboid(half.x, half.y, half.z);
            LinkShape {
                link,
                name: name.clone(),
                local: origin
                    * Isometry3::translation(
                        (b.mins.x + b.maxs.x) / 2.0,
                        (b.mins.y + b.maxs.y) / 2.0,
                        (b.mins.z + b.maxs.z) / 2.0,
                    ),
                shape,
                center: Point3::origin(),
                radius: half.norm(),
            }
        })
        .collect())
}

/// The points' principal axes (columns, right-handed) and their mean.
fn principal_axes(points: &[Point3<f32>]) -> (nalgebra::Matrix3<f32>, Vector3<f32>) {
    let n = points.len() as f32;
    let mean = points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n.max(1.0);
    let covariance = points.iter().fold(nalgebra::Matrix3::zeros(), |a, p| {
        let d = p.coords - mean;
        a + d * d.transpose()
    });
    let eigen = covariance.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|a, b| eigen.eigenvalues[*b].total_cmp(&eigen.eigenvalues[*a]));
    let x = eigen.eigenvectors.column(order[0]).normalize();
    let y = eigen.eigenvectors.column(order[1]).normalize();
    let z = x.cross(&y);
    (nalgebra::Matrix3::from_columns(&[x, y, z]), mean)
}

/// The tighter (by volume) of two shapes that hold every point by construction, with its
/// placement in the points' frame: the capsule along the principal axis whose segment
/// spans the points along it and whose radius is the farthest point's distance from that
/// segment, and the box on the principal axes around them. A gripper's squat base is far
/// tighter in a box; a forearm in a capsule.
fn hull_around(points: &[Point3<f32>]) -> Option<(Isometry3<f32>, SharedShape)> {
    if points.is_empty() {
        return None;
    }
    let (axes, mean) = principal_axes(points);
    let (mut lo, mut hi) = (
        Vector3::repeat(f32::INFINITY),
        Vector3::repeat(f32::NEG_INFINITY),
    );
    for p in points {
        let t = axes.transpose() * (p.coords - mean);
        lo = lo.inf(&t);
        hi = hi.sup(&t);
    }
    if !lo.iter().chain(hi.iter()).all(|v| v.is_finite()) {
        return None;
    }
    let axis = axes.column(0).into_owned();
    let (a, b) = (
        Point3::from(mean + axis * lo.x),
        Point3::from(mean + axis * hi.x),
    );
    let segment = parry3d::shape::Segment::new(a, b);
    let radius = points
        .iter()
        .map(|p| parry3d::query::PointQuery::distance_to_local_point(&segment, p, true))
        .fold(0.0f32, f32::max);
    // A hair more, so that rounding in the distance queries never leaves a vertex out.
    let radius = radius * 1.0001 + 1e-6;
    let half = (hi - lo) / 2.0 * 1.0001 + Vector3::repeat(1e-6);
    let capsule_volume =
        std::f32::consts::PI * radius * radius * ((hi.x - lo.x) + 4.0 * radius / 3.0);
    let box_volume = 8.0 * half.x * half.y * half.z;
    if capsule_volume <= box_volume {
        return Some((Isometry3::identity(), SharedShape::capsule(a, b, radius)));
    }
    let centre = mean + axes * ((lo + hi) / 2.0);
    let rotation =
        UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(axes));
    Some((
        Isometry3::from_parts(centre.into(), rotation),
        SharedShape::cuboid(half.x, half.y, half.z),
    ))
}

/// The vertices of an STL mesh (binary or ASCII), in the mesh's units.
pub fn read_stl(path: &Path) -> Result<Vec<Point3<f32>>, RobotError> {
    let mesh = read_indexed(path)?;
    Ok(mesh
        .vertices
        .iter()
        .map(|v| Point3::new(v[0], v[1], v[2]))
        .collect())
}

/// The triangles of an STL mesh (binary or ASCII), in the mesh's units.
pub fn read_stl_triangles(path: &Path) -> Result<Vec<[Point3<f32>; 3]>, RobotError> {
    let mesh = read_indexed(path)?;
    let vertex = |i: usize| {
        mesh.vertices
            .get(i)
            .map(|v| Point3::new(v[0], v[1], v[2]))
            .ok_or_else(|| RobotError::Mesh {
                file: path.to_path_buf(),
                message: format!("a triangle names vertex {i}, which the mesh lacks"),
            })
    };
    mesh.faces
        .iter()
        .map(|f| {
            Ok([
                vertex(f.vertices[0])?,
                vertex(f.vertices[1])?,
                vertex(f.vertices[2])?,
            ])
        })
        .collect()
}

fn read_indexed(path: &Path) -> Result<stl_io::IndexedMesh, RobotError> {
    let file = std::fs::File::open(path).map_err(|source| RobotError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut reader = std::io::BufReader::new(file);
    let mesh = stl_io::read_stl(&mut reader).map_err(|e| RobotError::Mesh {
        file: path.to_path_buf(),
        message: e.to_string(),
    })?;
    if mesh.vertices.is_empty() {
        return Err(RobotError::Mesh {
            file: path.to_path_buf(),
            message: "no triangles".into(),
        });
    }
    Ok(mesh)
}
