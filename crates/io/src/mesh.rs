//! Collision meshes of robot descriptions as triangles: STL (binary or ASCII, `stl_io`),
//! Wavefront OBJ (`tobj`) and COLLADA (`mesh-loader`, the file's unit applied), told apart by
//! the file extension.

use std::path::Path;

use emg_kinematics::Vec3;

/// Why a mesh file cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file cannot be opened or read.
    #[error("cannot read mesh {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a mesh of its kind.
    #[error("mesh {path} is not a valid {kind} file: {message}")]
    Malformed {
        /// The file.
        path: String,
        /// `STL`, `OBJ` or `COLLADA`.
        kind: &'static str,
        /// The reader's message.
        message: String,
    },
    /// The extension names no supported format.
    #[error(
        "mesh {path}: unsupported format (read: .stl, .obj, .dae; convert others to one of them)"
    )]
    Unsupported {
        /// The file.
        path: String,
    },
    /// A vertex is not a finite number.
    #[error("mesh {path} holds a vertex that is not finite")]
    NotFinite {
        /// The file.
        path: String,
    },
}

/// The triangles of `faces`, each its three corners (`None` for a vertex the file does not
/// hold, which makes the `kind` file at `path` malformed).
fn triangles_of(
    faces: impl Iterator<Item = [Option<Vec3>; 3]>,
    path: &str,
    kind: &'static str,
) -> Result<Vec<[Vec3; 3]>, MeshError> {
    faces
        .map(|corners| match corners {
            [Some(a), Some(b), Some(c)] => Ok([a, b, c]),
            _ => Err(MeshError::Malformed {
                path: path.to_string(),
                kind,
                message: "a face names a vertex the file does not hold".into(),
            }),
        })
        .collect()
}

/// The triangles of the mesh file at `path` (in the file's units).
pub fn read_mesh(path: &Path) -> Result<Vec<[Vec3; 3]>, MeshError> {
    let name = path.display().to_string();
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let triangles = match extension.as_str() {
        "stl" => {
            let mut file = std::fs::File::open(path).map_err(|source| MeshError::Io {
                path: name.clone(),
                source,
            })?;
            let mesh = stl_io::read_stl(&mut file).map_err(|e| MeshError::Malformed {
                path: name.clone(),
                kind: "STL",
                message: e.to_string(),
            })?;
            let vertex = |i: usize| {
                let v = mesh.vertices[i];
                Vec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
            };
            mesh.faces
                .iter()
                .map(|face| face.vertices.map(vertex))
                .collect::<Vec<_>>()
        }
        "obj" => {
            let options = tobj::LoadOptions {
                triangulate: true,
                single_index: true,
                ..tobj::LoadOptions::default()
            };
            let (models, _materials) =
                tobj::load_obj(path, &options).map_err(|e| MeshError::Malformed {
                    path: name.clone(),
                    kind: "OBJ",
                    message: e.to_string(),
                })?;
            let faces = models.iter().flat_map(|model| {
                let mesh = &model.mesh;
                let vertex = move |i: u32| {
                    let k = 3 * i as usize;
                    mesh.positions
                        .get(k..k + 3)
                        .map(|p| Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
                };
                mesh.indices
                    .chunks_exact(3)
                    .map(move |face| [vertex(face[0]), vertex(face[1]), vertex(face[2])])
            });
            triangles_of(faces, &name, "OBJ")?
        }
        "dae" => {
            let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
                path: name.clone(),
                source,
            })?;
            let scene =
                mesh_loader::collada::from_slice(&bytes).map_err(|e| MeshError::Malformed {
                    path: name.clone(),
                    kind: "COLLADA",
                    message: e.to_string(),
                })?;
            let faces = scene.meshes.iter().flat_map(|mesh| {
                let vertex = move |i: u32| {
                    mesh.vertices
                        .get(i as usize)
                        .map(|p| Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
                };
                mesh.faces.iter().map(move |face| face.map(vertex))
            });
            triangles_of(faces, &name, "COLLADA")?
        }
        _ => return Err(MeshError::Unsupported { path: name }),
    };
    if triangles
        .iter()
        .flatten()
        .any(|v| !v.iter().all(|x| x.is_finite()))
    {
        return Err(MeshError::NotFinite { path: name });
    }
    Ok(triangles)
}

/// Volume (m³) enclosed by a closed triangle mesh (the absolute sum of signed tetrahedra; for an
/// open mesh, a number without meaning).
pub fn mesh_volume(triangles: &[[Vec3; 3]]) -> f64 {
    triangles
        .iter()
        .map(|[a, b, c]| a.dot(&b.cross(c)) / 6.0)
        .sum::<f64>()
        .abs()
}
