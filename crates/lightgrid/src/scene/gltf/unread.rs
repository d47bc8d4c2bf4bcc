//! What a file holds that lightgrid does not apply, each said once per file with what is
//! drawn instead (README "glTF scenes": nothing is ignored in silence). A feature of several
//! materials or meshes is one warning naming the first few.

use super::json::{Root, TextureRef};

/// At most this many indices are named in one warning ("materials 0, 3, 7 and 2 more").
const NAMED: usize = 4;

/// "material 3" or "materials 0, 3, 7 and 2 more".
fn which(what: &str, indices: &[usize]) -> String {
    let shown: Vec<String> = indices.iter().take(NAMED).map(usize::to_string).collect();
    let more = match indices.len().saturating_sub(NAMED) {
        0 => String::new(),
        n => format!(" and {n} more"),
    };
    let plural = match what {
        "mesh" => "meshes".to_string(),
        w => format!("{w}s"),
    };
    match indices.len() {
        1 => format!("{what} {}", shown[0]),
        _ => format!("{plural} {}{more}", shown.join(", ")),
    }
}

/// The indices of `items` for which `has` holds.
fn having<T>(items: &[T], has: impl Fn(&T) -> bool) -> Vec<usize> {
    (items.iter().enumerate())
        .filter(|(_, x)| has(x))
        .map(|(i, _)| i)
        .collect()
}

/// Does a texture reference read a coordinate set past 1?
fn other_set(t: &Option<TextureRef>) -> bool {
    t.as_ref().is_some_and(|t| t.set() > 1)
}

/// One warning for `indices` of `what` (none when empty).
/// `text` starts with its verb in the singular ("has", "samples"), made plural for several.
fn say(out: &mut Vec<String>, indices: Vec<usize>, what: &str, text: &str) {
    if indices.is_empty() {
        return;
    }
    let (verb, rest) = text.split_once(' ').unwrap_or((text, ""));
    let verb = match (indices.len(), verb) {
        (1, v) => v.to_string(),
        (_, "has") => "have".to_string(),
        (_, v) => v.strip_suffix('s').unwrap_or(v).to_string(),
    };
    out.push(format!("{} {verb} {rest}", which(what, &indices)));
}

/// Every warning for the parts of `root` that are not applied.
pub(super) fn warnings(root: &Root) -> Vec<String> {
    let mut out = Vec::new();
    let mats = &root.materials;
    fn pbr(m: &super::json::MaterialDef) -> Option<&super::json::Pbr> {
        m.pbr_metallic_roughness.as_ref()
    }
    say(
        &mut out,
        having(mats, |m| {
            let pbr = pbr(m);
            [&m.emissive_texture, &m.normal_texture, &m.occlusion_texture]
                .into_iter()
                .chain(pbr.map(|p| &p.base_color_texture))
                .chain(pbr.map(|p| &p.metallic_roughness_texture))
                .any(other_set)
        }),
        "material",
        "samples a texture with texture coordinate set 2 or above, which is not read: set 0 is used",
    );
    // Morph targets change the shape only with a weight other than 0 (the mesh's default or
    // a node's).
    let weighted = |w: &Option<Vec<f32>>| w.as_ref().is_some_and(|w| w.iter().any(|x| *x != 0.0));
    let morphed: Vec<usize> = having(&root.meshes, |m| {
        m.primitives.iter().any(|p| !p.targets.is_empty())
    })
    .into_iter()
    .filter(|&i| {
        weighted(&root.meshes[i].weights)
            || root
                .nodes
                .iter()
                .any(|n| n.mesh == Some(i) && weighted(&n.weights))
    })
    .collect();
    say(
        &mut out,
        morphed,
        "mesh",
        "has morph targets with weights other than 0, which are not applied: its base shape is drawn",
    );
    if !root.skins.is_empty() || root.nodes.iter().any(|n| n.skin.is_some()) {
        out.push(format!(
            "{} skin(s) are not applied: skinned meshes are drawn in their bind pose",
            root.skins.len().max(1)
        ));
    }
    // Magnification NEAREST is applied, and minification within mip levels is too fine to
    // see; a minification without mipmaps (NEAREST, LINEAR) or with the nearest mip level
    // (*_MIPMAP_NEAREST) is drawn with linearly blended mip levels.
    let unmipped = |f: Option<u32>| f.is_some_and(|f| matches!(f, 9728 | 9729 | 9984 | 9985));
    say(
        &mut out,
        having(&root.samplers, |s| unmipped(s.min_filter)),
        "sampler",
        "asks for a minification filter without mipmaps or with the nearest mip level, which is not applied: textures are minified with blended mip levels",
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn root(json: &str) -> Root {
        serde_json::from_str(json).unwrap()
    }

    #[test]
    fn each_unapplied_feature_is_one_warning_naming_where() {
        let r = root(
            r#"{
            "materials": [
                {"normalTexture": {"index": 0}, "occlusionTexture": {"index": 0}},
                {"pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 0},
                  "baseColorTexture": {"index": 0, "texCoord": 2}}},
                {"normalTexture": {"index": 0, "texCoord": 3}}
            ],
            "meshes": [
                {"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}}]},
                {"primitives": [{"attributes": {"POSITION": 0}, "targets": [{"POSITION": 2}]}],
                 "weights": [0.0]},
                {"primitives": [{"attributes": {"POSITION": 0}, "targets": [{"POSITION": 2}]}]}
            ],
            "nodes": [{"mesh": 1, "weights": [0.5]}, {"mesh": 2}, {"skin": 0}],
            "skins": [{"joints": [0]}],
            "samplers": [{"minFilter": 9728}, {"magFilter": 9728, "minFilter": 9986}]
        }"#,
        );
        let w = warnings(&r);
        let has = |needle: &str| {
            let found: Vec<&String> = w.iter().filter(|x| x.contains(needle)).collect();
            assert_eq!(found.len(), 1, "{needle}: {w:#?}");
            found[0].clone()
        };
        // Read: normal, occlusion and metallic-roughness textures, sets 0 and 1, COLOR_0.
        assert!(has("coordinate set 2").starts_with("materials 1, 2 "));
        // Mesh 1 is weighted by its node; mesh 2's targets have no weight.
        assert!(has("morph targets").starts_with("mesh 1 "));
        assert!(has("bind pose").starts_with("1 skin"));
        assert!(has("minification").starts_with("sampler 0 "));
        assert_eq!(w.len(), 4, "{w:#?}");
        assert!(warnings(&root("{}")).is_empty());
    }

    #[test]
    fn long_lists_name_the_first_few() {
        assert_eq!(
            which("mesh", &[0, 1, 2, 3, 4, 5]),
            "meshes 0, 1, 2, 3 and 2 more"
        );
    }
}
