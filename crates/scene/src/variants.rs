//! `KHR_materials_variants`: named alternative materials for a file's primitives (a shoe in
//! three colourways, a sofa in several fabrics). The root lists the variants' names; each
//! primitive may map some of them to other materials. One variant is drawn at a time
//! (`--variant NAME`, [`crate::LoadOptions::variant`]); without one, the primitives' own
//! materials, as the extension specifies.

use crate::context::Ctx;
use crate::error::SceneError;
use serde_json::Value;

/// The file's variants by name, and the one chosen (its index), both checked.
pub(crate) struct Variants {
    pub names: Vec<String>,
    pub chosen: Option<usize>,
}

/// Reads the root's variant list and resolves `chosen` (a name, compared exactly and then
/// without regard to case) against it: an error naming the field for a malformed list, and
/// naming the variants a file has when the name is none of them.
pub(crate) fn read(ctx: &Ctx, raw: &Value, chosen: Option<&str>) -> Result<Variants, SceneError> {
    let at = "extensions.KHR_materials_variants.variants";
    let names: Vec<String> = match raw.pointer("/extensions/KHR_materials_variants") {
        None => Vec::new(),
        Some(ext) => {
            let list = ext
                .get("variants")
                .and_then(Value::as_array)
                .ok_or_else(|| ctx.invalid(at, "is missing or not an array of variants"))?;
            list.iter()
                .enumerate()
                .map(|(i, v)| {
                    v.get("name")
                        .and_then(Value::as_str)
                        .map(str::to_string)
                        .ok_or_else(|| ctx.invalid(format!("{at}[{i}].name"), "is missing or not a string"))
                })
                .collect::<Result<_, _>>()?
        }
    };
    let chosen = match chosen {
        None => None,
        Some(name) => {
            let found = names
                .iter()
                .position(|n| n == name)
                .or_else(|| names.iter().position(|n| n.eq_ignore_ascii_case(name)));
            match found {
                Some(i) => Some(i),
                None if names.is_empty() => {
                    return Err(ctx.invalid(
                        "extensions",
                        format!(
                            "--variant {name}: the file has no material variants (KHR_materials_variants)"
                        ),
                    ));
                }
                None => {
                    return Err(ctx.invalid(
                        at,
                        format!("--variant {name}: the file has no such variant; it has {}", quoted(&names)),
                    ));
                }
            }
        }
    };
    Ok(Variants { names, chosen })
}

/// `'a', 'b' and 'c'`.
pub(crate) fn quoted(names: &[String]) -> String {
    let q: Vec<String> = names.iter().map(|n| format!("'{n}'")).collect();
    match q.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => q.join(""),
    }
}

impl Variants {
    /// The material primitive `(mesh, prim)` draws in the chosen variant: its mapping's material
    /// where one names the variant, else `None` (the primitive's own). Every mapping is checked,
    /// chosen or not: a material or variant index that names none is an error naming the field.
    pub(crate) fn material(
        &self,
        ctx: &Ctx,
        raw: &Value,
        (mesh, prim): (usize, usize),
        materials: usize,
    ) -> Result<Option<usize>, SceneError> {
        let path = format!("/meshes/{mesh}/primitives/{prim}/extensions/KHR_materials_variants");
        let Some(ext) = raw.pointer(&path) else { return Ok(None) };
        let at = format!("meshes[{mesh}].primitives[{prim}].extensions.KHR_materials_variants.mappings");
        let mappings = ext
            .get("mappings")
            .and_then(Value::as_array)
            .ok_or_else(|| ctx.invalid(&at, "is missing or not an array"))?;
        let mut found = None;
        for (k, m) in mappings.iter().enumerate() {
            let material = m.get("material").and_then(Value::as_u64).filter(|&i| (i as usize) < materials);
            let Some(material) = material else {
                return Err(ctx.invalid(
                    format!("{at}[{k}].material"),
                    format!("is not the index of one of the file's {materials} materials"),
                ));
            };
            let vs = m
                .get("variants")
                .and_then(Value::as_array)
                .ok_or_else(|| ctx.invalid(format!("{at}[{k}].variants"), "is missing or not an array"))?;
            for (j, v) in vs.iter().enumerate() {
                let Some(v) = v.as_u64().filter(|&v| (v as usize) < self.names.len()) else {
                    return Err(ctx.invalid(
                        format!("{at}[{k}].variants[{j}]"),
                        format!("{v} is not the index of one of the file's {} variants", self.names.len()),
                    ));
                };
                if Some(v as usize) == self.chosen && found.is_none() {
                    found = Some(material as usize);
                }
            }
        }
        Ok(found)
    }

    /// The warning for a file drawn without choosing among its variants, or `None`.
    pub(crate) fn unchosen_warning(&self) -> Option<String> {
        (self.chosen.is_none() && !self.names.is_empty()).then(|| {
            format!(
                "KHR_materials_variants: the file has the material variants {}; the default materials are \
                 drawn (choose one with --variant NAME)",
                quoted(&self.names)
            )
        })
    }
}
