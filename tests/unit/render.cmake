if(TARGET sp_render)
  sp_unit_test(render LIBS sp_render)
endif()

# `sketchpose render` on CesiumMan: the PNG exists and has the asked size.
# Skipped (exit 77) when ../shared/data is absent.
if(TARGET sketchpose)
  add_test(NAME render_cli_cesiumman
    COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/e2e/render_png.sh $<TARGET_FILE:sketchpose>
            ${SP_SHARED_DATA}/gltf/CesiumMan/CesiumMan.glb ${PROJECT_BINARY_DIR}/tmp/render_cesiumman.png 400 300)
  set_tests_properties(render_cli_cesiumman PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 120)
endif()
