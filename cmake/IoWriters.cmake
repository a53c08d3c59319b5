# IoWriters.cmake: the result documents' writer tables (src/io/write.h), generated from the
# annotated result schemas ("x-prsm" "write", "field", ...) by scripts/gen-io-writers.py (Python
# standard library only) into <build>/generated/prsm_io_writers.{h,c} and compiled into
# prsm_core. The generator fails the build when a property of a written object says nothing or
# names a member its struct lacks.
set(PRSM_IO_WRITERS_SCRIPT ${PROJECT_SOURCE_DIR}/scripts/gen-io-writers.py)
file(GLOB PRSM_IO_WRITER_SCHEMAS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/schemas/*.schema.json)
file(GLOB_RECURSE PRSM_IO_WRITER_HEADERS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/*.h)
set(PRSM_IO_WRITERS ${PROJECT_BINARY_DIR}/generated/prsm_io_writers.c ${PROJECT_BINARY_DIR}/generated/prsm_io_writers.h)
add_custom_command(
  OUTPUT ${PRSM_IO_WRITERS}
  COMMAND /usr/bin/python3 ${PRSM_IO_WRITERS_SCRIPT} --out-dir ${PROJECT_BINARY_DIR}/generated
          --src ${PROJECT_SOURCE_DIR}/src ${PRSM_IO_WRITER_SCHEMAS}
  DEPENDS ${PRSM_IO_WRITERS_SCRIPT} ${PROJECT_SOURCE_DIR}/scripts/gen-io-tables.py ${PRSM_IO_WRITER_SCHEMAS}
          ${PRSM_IO_WRITER_HEADERS}
  COMMENT "Result writer tables from schemas/ (x-prsm)"
  VERBATIM)
target_sources(prsm_core PRIVATE ${PRSM_IO_WRITERS})
