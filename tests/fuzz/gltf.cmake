# fuzz_gltf: libFuzzer over the glTF loader (SP_FUZZ=ON, clang only).
sp_fuzz_target(gltf LIBS sp::gltf INSTRUMENT sp_gltf RUNS 2000)
