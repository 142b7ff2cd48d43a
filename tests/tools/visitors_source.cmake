# Build step of sp_visitors_data (tests/bench/visitors.cmake): records in
# STAMP whether the Quick, Draw! data QD is there now, rewriting the file only
# when that changed. The visitors' set is rebuilt when the file changes, so
# data that appears (or goes) after configuring is picked up by the next
# build, not only by the next configure.
# -D QD=<quickdraw folder> STAMP=<file>
if(EXISTS ${QD})
  set(now "with ${QD}\n")
else()
  set(now "without ${QD}\n")
endif()
set(was "")
if(EXISTS ${STAMP})
  file(READ ${STAMP} was)
endif()
if(NOT was STREQUAL now)
  file(WRITE ${STAMP} "${now}")
endif()
