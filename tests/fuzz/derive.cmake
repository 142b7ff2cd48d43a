# fuzz_derive: libFuzzer over deriving a part from a rigged glTF made
# elsewhere (sp_part_derive, with the outline tracer) (SP_FUZZ=ON, clang
# only). Seeds: the skinned glTF seeds of corpus/gltf, two_bone_clip.gltf
# (two_bone.gltf with a three-key clip) and collapsed_skin.glb (its first
# finding: a nearly singular skin blend, now refused by sp_part_derive).
# sp_gltf, which derive.c and outline.c are part of, is instrumented by
# gltf.cmake. Run longer by hand, e.g.
#   build-fuzz/tests/fuzz_derive -max_total_time=300 /tmp/derive-corpus tests/fuzz/corpus/derive
sp_fuzz_target(derive LIBS sp::gltf RUNS 500 MAX_LEN 65536)
