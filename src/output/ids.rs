//! The id pass's legend: `{scene}_ids.json` beside the frames.

use std::io::Write;

use crate::error::Error;
use crate::scene::Scene;

/// `{scene}_ids.json` in the output directory: what the id pass's numbers
/// stand for (`object_id`: 1 + the index of the model's part over the
/// models' parts in order, named `model` or `model/node`; `material_id`:
/// 1 + the material's index over the models' materials in order, with
/// the model's first object id; 0 = nothing).
pub fn write(scene: &Scene) -> Result<(), Error> {
    let mut objects = Vec::new();
    let mut materials = Vec::new();
    for m in &scene.models {
        let first = objects.len() + 1;
        for name in m.object_names() {
            objects.push(serde_json::json!({ "id": objects.len() + 1, "name": name }));
        }
        for mat in &m.materials {
            materials.push(serde_json::json!({
                "id": materials.len() + 1,
                "name": mat.name,
                "object_id": first,
            }));
        }
    }
    let doc = serde_json::json!({
        "background": 0,
        "objects": objects,
        "materials": materials,
    });
    let path = scene.output.dir.join(format!("{}_ids.json", scene.stem));
    super::write_atomic(&path, |w| {
        serde_json::to_writer_pretty(&mut *w, &doc).map_err(|e| Error::Encode {
            path: path.clone(),
            message: e.to_string(),
        })?;
        w.write_all(b"\n").map_err(|e| Error::io(&path, e))
    })
}
