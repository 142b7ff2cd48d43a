# fuzz_derive: libFuzzer over deriving a part from a rigged glTF made
# elsewhere (sp_part_derive, with the outline tracer) (SP_FUZZ=ON, clang
# only). Seeds: the skinned glTF seeds of corpus/gltf, two_bone_clip.gltf
# (two_bone.gltf with a three-key clip) and its findings: collapsed_skin.glb
# (a nearly singular skin blend under the outline, now refused) and
# flat_stick.glb (under the stick figure only, now left out of it).
# sp_gltf, which derive.c and outline.c are part of, is instrumented by
# gltf.cmake. Run longer by hand, e.g.
#   build-fuzz/tests/fuzz_derive -max_total_time=300 /tmp/derive-corpus tests/fuzz/corpus/derive
sp_fuzz_target(derive LIBS sp::gltf RUNS 500 MAX_LEN 65536)
