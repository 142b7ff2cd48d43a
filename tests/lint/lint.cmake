# Structure checks that CI runs with the tests (issue 18): no function in
# solver/src is longer than 120 lines (tests/lint/function_length.c says how
# a function is measured). The check is checked too: a generated function
# of 121 lines fails it and one of 120 lines, beside a longer initialiser,
# passes.
add_executable(function_length lint/function_length.c lint/lint_scan.c)
target_link_libraries(function_length PRIVATE sp_flags)
file(GLOB SP_SOLVER_C CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/solver/src/*.c)
add_test(NAME function_length_solver COMMAND function_length 120 ${SP_SOLVER_C})
# Everywhere else 150 lines, the functions that are longer listed in
# lint/long_functions.txt with their lengths: none grows, none joins them
# unlisted, and an entry goes when its function is split.
file(GLOB SP_PRODUCT_C CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/sketchio/src/*.c ${PROJECT_SOURCE_DIR}/classifier/src/*.c
     ${PROJECT_SOURCE_DIR}/partdb/src/*.c ${PROJECT_SOURCE_DIR}/app/*/*.c ${PROJECT_SOURCE_DIR}/app/*/src/*.c
     ${PROJECT_SOURCE_DIR}/assets/gen/*.c ${PROJECT_SOURCE_DIR}/assets/face/*.c)
add_test(NAME function_length_product
         COMMAND function_length 150 --allow ${CMAKE_CURRENT_SOURCE_DIR}/lint/long_functions.txt ${SP_PRODUCT_C})

set(sp_lint_dir ${CMAKE_CURRENT_BINARY_DIR}/lint)
foreach(n 120 121)
  math(EXPR body "${n} - 2")
  string(REPEAT "    x += 1; /* { */\n" ${body} lines)
  string(REPEAT "    1,\n" 200 table)
  file(WRITE ${sp_lint_dir}/f${n}.c
    "static const int table[] = {\n${table}};\n// a comment with a { brace\nstatic int f(int x)\n{\n${lines}}\n")
endforeach()
add_test(NAME function_length_passes_120 COMMAND function_length 120 ${sp_lint_dir}/f120.c)
# A check that must fail: exit 1 and the message (PASS_REGULAR_EXPRESSION
# alone ignores the exit code, so a lint that printed and passed would pass).
function(sp_lint_fails name msg exe)
  add_test(NAME ${name} COMMAND sh -c "out=\$(\"\$0\" \"\$@\"); rc=\$?; printf '%s\\n' \"\$out\"; [ \$rc -eq 1 ] && printf '%s\\n' \"\$out\" | grep -qF -- '${msg}'"
           $<TARGET_FILE:${exe}> ${ARGN})
endfunction()
sp_lint_fails(function_length_fails_121 "f121.c:205: f is 121 lines, limit 120" function_length 120 ${sp_lint_dir}/f121.c)
# The list: f listed at 121 passes; listed at 120 it fails; a listed function
# now within the limit, or one that is not there, fails.
foreach(entry "121:pass" "120:grew")
  string(REPLACE ":" ";" pair ${entry})
  list(GET pair 0 lines)
  list(GET pair 1 what)
  file(WRITE ${sp_lint_dir}/allow_${what}.txt "# a comment\nf121.c f ${lines}\n")
endforeach()
file(WRITE ${sp_lint_dir}/allow_stale.txt "f120.c f 130\n")
file(WRITE ${sp_lint_dir}/allow_missing.txt "f121.c f 121\nf121.c g 300\n")
add_test(NAME function_length_allow_passes COMMAND function_length 120 --allow ${sp_lint_dir}/allow_pass.txt ${sp_lint_dir}/f121.c)
sp_lint_fails(function_length_allow_grew "f is 121 lines, limit 120" function_length 120 --allow ${sp_lint_dir}/allow_grew.txt ${sp_lint_dir}/f121.c)
sp_lint_fails(function_length_allow_stale "within 120: take it off the list" function_length 120 --allow ${sp_lint_dir}/allow_stale.txt
              ${sp_lint_dir}/f120.c)
sp_lint_fails(function_length_allow_missing "no function g: take it off the list" function_length 120 --allow ${sp_lint_dir}/allow_missing.txt
              ${sp_lint_dir}/f121.c)

# The posing commands link neither OpenCV nor SQLite (the solver's own FLANN
# is fine): no classifier, no database. The check is checked too: the whole
# sketchpose, which classifies and trains, does link them.
if(TARGET sp_pose_cmds)
  add_executable(pose_links lint/pose_links.c)
  target_link_libraries(pose_links PRIVATE sp_pose_cmds)
  set(sp_forbidden "libopencv|libsqlite3")
  # The binaries come in as $0, not pasted into the script: a build path
  # with a space (or any character) stays one word.
  add_test(NAME pose_links_no_classifier
           COMMAND sh -c "\"\$0\" >/dev/null && ldd \"\$0\" > pose_links.ldd && ! grep -E '${sp_forbidden}' pose_links.ldd"
                   $<TARGET_FILE:pose_links>)
  add_test(NAME pose_links_check_sees_opencv COMMAND sh -c "ldd \"\$0\" | grep -E '${sp_forbidden}'" $<TARGET_FILE:sketchpose>)
endif()

# No public header names a third-party library (tests/lint/public_headers.c
# says what counts): the headers under <library>/include/sp are all a user
# compiles against. Checked too: a header that includes GLFW, returns a cJSON
# tree and takes a cv::Mat fails on each; one that names them only in
# comments and strings passes.
add_executable(public_headers lint/public_headers.c lint/lint_scan.c)
target_link_libraries(public_headers PRIVATE sp_flags)
file(GLOB SP_PUBLIC_HEADERS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/*/include/sp/*.h ${PROJECT_SOURCE_DIR}/app/*/include/sp/*.h)
add_test(NAME public_headers_no_third_party COMMAND public_headers ${SP_PUBLIC_HEADERS})
file(WRITE ${sp_lint_dir}/foreign.h
  "#include <stdbool.h>\n#include <GLFW/glfw3.h>\nstruct cJSON* sp_x_json(void);\nvoid sp_x_show(const cv::Mat* m);\n")
file(WRITE ${sp_lint_dir}/clean.h
  "#include <stdint.h>\n#include \"sp/result.h\"\n/// Built on cJSON and GLFW (glfwPollEvents); FLANN's kd-tree.\n"
  "#define SP_X_NAME \"cJSON\"\nsp_result sp_x_json(char** json, sp_error* err); // free() it, no cJSON_Delete\n"
  "int sp_glyph_count(void);\n")
sp_lint_fails(public_headers_fails_foreign_include "foreign.h:2: includes <GLFW/glfw3.h>" public_headers ${sp_lint_dir}/foreign.h)
sp_lint_fails(public_headers_fails_foreign_type "foreign.h:3: names cJSON" public_headers ${sp_lint_dir}/foreign.h)
sp_lint_fails(public_headers_fails_foreign_scope "foreign.h:4: names a C++ scope" public_headers ${sp_lint_dir}/foreign.h)
add_test(NAME public_headers_passes_comments COMMAND public_headers ${sp_lint_dir}/clean.h)

# --max-ms has one range check (sp_cli_check_max_ms, app/common/cli.c) that
# pose, drawover and dragon call; a command's own copy of the range would
# drift from the others' (it was written three times).
# grep's exit 1 (no copy found) passes; 0 (a copy) and 2 (a file it could
# not read: a `!` alone would pass that) fail. The folder comes in as $0.
set(sp_max_ms_check "grep -n 'sp_cli_check_double([^;]*--max-ms' \"\$0\"/*.c; [ \$? -eq 1 ]")
add_test(NAME cli_max_ms_checked_once COMMAND sh -c "${sp_max_ms_check}" ${PROJECT_SOURCE_DIR}/app/src)
# The check is checked: a folder with a copy fails, one with no .c files
# (grep cannot read the unexpanded glob) fails, a clean one passes.
file(WRITE ${sp_lint_dir}/max_ms_copy/cmd.c "sp_cli_check_double(argv[i], \"--max-ms\", 0, 1e9);\n")
file(WRITE ${sp_lint_dir}/max_ms_clean/cmd.c "sp_cli_check_max_ms(argv[i]);\n")
file(MAKE_DIRECTORY ${sp_lint_dir}/max_ms_none)
add_test(NAME cli_max_ms_check_passes_clean COMMAND sh -c "${sp_max_ms_check}" ${sp_lint_dir}/max_ms_clean)
add_test(NAME cli_max_ms_check_fails_copy COMMAND sh -c "${sp_max_ms_check}" ${sp_lint_dir}/max_ms_copy)
add_test(NAME cli_max_ms_check_fails_unreadable COMMAND sh -c "${sp_max_ms_check}" ${sp_lint_dir}/max_ms_none)
set_tests_properties(cli_max_ms_check_fails_copy cli_max_ms_check_fails_unreadable PROPERTIES WILL_FAIL TRUE)
