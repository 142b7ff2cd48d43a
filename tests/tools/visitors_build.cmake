# Builds the visitors' set into OUT with the Quick, Draw! data when QD is
# there at build time, and copies STAMP (visitors_source.cmake) to OUT/built:
# the tests compare it with the data they find, so a set built without the
# data is not judged as if it had it.
# -D TOOL=sp-visitors-make DESIGNS=<designs.json> QD=<quickdraw folder> OUT=<folder> LOG=<file> STAMP=<file>
file(REMOVE_RECURSE ${OUT})
set(qd_args)
if(EXISTS ${QD})
  set(qd_args --quickdraw ${QD})
endif()
execute_process(COMMAND ${TOOL} --designs ${DESIGNS} ${qd_args} --out ${OUT} OUTPUT_FILE ${LOG} RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "sp-visitors-make failed (${rc}), see ${LOG}")
endif()
file(READ ${STAMP} source)
file(WRITE ${OUT}/built "${source}")
