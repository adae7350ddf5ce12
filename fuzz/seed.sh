#!/usr/bin/env bash
# Seeds fuzz/corpus/<target>/ from what the repository holds: the odd and
# malformed files of tests/wild, the showcase's and the tests' models and
# scenes. Run from anywhere; existing corpus files are kept.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
corpus="$root/fuzz/corpus"
mkdir -p "$corpus"/{obj_mtl,gltf,scene_toml,render,texture,output_names,fbx,usd}

# obj_mtl: OBJ bytes, a NUL, MTL bytes (the first .mtl in the same folder).
n=0
while IFS= read -r -d '' obj; do
  mtl="$(ls "$(dirname "$obj")"/*.mtl 2>/dev/null | head -n1 || true)"
  size=$(stat -c %s "$obj")
  [ "$size" -gt 200000 ] && continue
  { cat "$obj"; printf '\0'; [ -n "$mtl" ] && cat "$mtl"; } > "$corpus/obj_mtl/seed_$n"
  n=$((n + 1))
done < <(find "$root/tests/wild" "$root/assets" "$root/tests/data" -name '*.obj' -print0)

# gltf: the glTF and GLB files.
while IFS= read -r -d '' g; do
  size=$(stat -c %s "$g")
  [ "$size" -gt 200000 ] && continue
  cp "$g" "$corpus/gltf/$(basename "$g")"
done < <(find "$root/tests/wild" "$root/assets" "$root/tests/data" \( -name '*.gltf' -o -name '*.glb' \) -print0)

# fbx: the FBX files.
while IFS= read -r -d '' f; do
  cp "$f" "$corpus/fbx/$(basename "$f")"
done < <(find "$root/tests/wild" -name '*.fbx' -print0)

# usd: the USD and 3MF files, each behind the byte that picks its
# extension.
while IFS= read -r -d '' f; do
  case "$f" in
    *.usda) pick='\000' ;;
    *.usdc) pick='\001' ;;
    *.usdz) pick='\002' ;;
    *) pick='\003' ;;
  esac
  { printf "$pick"; cat "$f"; } > "$corpus/usd/$(basename "$f")"
done < <(find "$root/tests/wild" \( -name '*.usda' -o -name '*.usdc' -o -name '*.usdz' -o -name '*.3mf' \) -print0)

# scene_toml: every scene, its model paths pointed at the fuzz assets.
while IFS= read -r -d '' s; do
  sed -E 's#^path = "[^"]*\.(obj|OBJ)"#path = "tri.obj"#; s#^path = "[^"]*\.(gltf|glb)"#path = "quad.gltf"#; s#"[^"]*\.(png|tga|jpg|hdr|exr)"#"tex.png"#g' \
    "$s" > "$corpus/scene_toml/$(basename "$s")"
done < <(find "$root/scenes" "$root/tests/scenes" "$root/tests/wild" "$root/tests/data" -name '*.toml' -print0)

# render: a few byte strings (geometry and settings are read from raw bytes).
for i in 0 1 2 3 4 5 6 7; do
  head -c $((64 + i * 48)) /dev/urandom > "$corpus/render/seed_$i"
done
printf '\x03\x01\x00\x00\x80\xbf\x00\x00\x80\xbf\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x80\xbf\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x01\x02' > "$corpus/render/seed_triangle"
# texture: the small images (every format the corpus holds).
while IFS= read -r -d '' img; do
  size=$(stat -c %s "$img")
  [ "$size" -gt 200000 ] && continue
  cp "$img" "$corpus/texture/$(basename "$img")"
done < <(find "$root/tests/wild" "$root/assets" "$root/tests/data" \( -name '*.png' -o -name '*.dds' -o -name '*.tga' -o -name '*.bmp' -o -name '*.tif' -o -name '*.jpg' -o -name '*.hdr' -o -name '*.ktx2' \) -print0)

# output_names: name, gif, video, scene camera, glTF camera (NUL-separated).
printf '{camera}_{frame:04}\0t.gif\0t.mp4\0front\0cam' > "$corpus/output_names/seed_plain"
printf '{scene}-{camera}\0../t.gif\0/tmp/t.mp4\0../../x\0a/b' > "$corpus/output_names/seed_escape"
printf '{camera}\0sub/{camera}.gif\0\0..\0.' > "$corpus/output_names/seed_dots"

echo "seeded $(ls "$corpus"/obj_mtl | wc -l) obj_mtl, $(ls "$corpus"/gltf | wc -l) gltf, $(ls "$corpus"/scene_toml | wc -l) scene_toml, $(ls "$corpus"/render | wc -l) render, $(ls "$corpus"/texture | wc -l) texture inputs in $corpus"
