# fuzz_model: libFuzzer over classifier models (sp_clf_from_bytes, then one
# classification with a model that loads) (SP_FUZZ=ON, clang only). Seeds:
# three tiny models trained on made-up rings, zigzags and lines, three of
# each (`sketchpose train --threads 1` with --words 8 --knn 2;
# --words 6 --knn 3 --pyramid 2 --no-tfidf --shape-weight 0.5; --words 5
# --knn 1 --no-pyramid --no-hellinger --no-mirror --picture-weight -1);
# test_classifier model_files checks that they still load. Run longer by hand, e.g.
#   build-fuzz/tests/fuzz_model -max_total_time=300 /tmp/model-corpus tests/fuzz/corpus/model
sp_fuzz_target(model LIBS sp::classifier INSTRUMENT sp_classifier RUNS 500 MAX_LEN 70000)
# The model format's checksum (model_checksum.h), to make a mutated file's right.
target_include_directories(fuzz_model PRIVATE ${PROJECT_SOURCE_DIR}/classifier/src)
