# Dragon-part classes: the hand-drawing model (partdb), the database's synthetic
# sketches, `sketchpose synth --parts`, and the dragon-part classifier criteria
# on a smaller set (the full 600/200 figures: bench_dragon_classes).
sp_unit_test(dragon_classes LIBS sp::partdb sp::classifier TIMEOUT 600)
target_include_directories(test_dragon_classes PRIVATE ${PROJECT_SOURCE_DIR}/partdb/src)
if(TARGET sketchpose)
  add_dependencies(test_dragon_classes sketchpose)
endif()
