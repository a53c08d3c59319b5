# IoTables.cmake: the document readers' field tables (src/io/doc.h), generated from the annotated
# JSON Schemas ("x-prsm") by scripts/gen-io-tables.py (Python standard library only) into
# <build>/generated/prsm_io_tables.{h,c} (and prsm_io_enums.h, prsm_vocab.h) and compiled into
# prsm_core. The generator fails the build when a schema property names no C member or a member
# of the struct is left unread.
set(PRSM_IO_TABLES_SCRIPT ${PROJECT_SOURCE_DIR}/scripts/gen-io-tables.py)
file(GLOB PRSM_IO_SCHEMAS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/schemas/*.schema.json)
# the structs the tables fill (the headers the schemas name, and those they include)
file(GLOB_RECURSE PRSM_IO_HEADERS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/*.h)
# prsm_vocab.h: the schemas' vocabularies as plain C (src/mc includes it); prsm_io_enums.h:
# the enum constants the schemas' "constants" generate
set(PRSM_IO_TABLES ${PROJECT_BINARY_DIR}/generated/prsm_io_tables.c ${PROJECT_BINARY_DIR}/generated/prsm_io_tables.h
    ${PROJECT_BINARY_DIR}/generated/prsm_io_enums.h ${PROJECT_BINARY_DIR}/generated/prsm_vocab.h)
add_custom_command(
  OUTPUT ${PRSM_IO_TABLES}
  COMMAND /usr/bin/python3 ${PRSM_IO_TABLES_SCRIPT} --out-dir ${PROJECT_BINARY_DIR}/generated
          --src ${PROJECT_SOURCE_DIR}/src ${PRSM_IO_SCHEMAS}
  DEPENDS ${PRSM_IO_TABLES_SCRIPT} ${PRSM_IO_SCHEMAS} ${PRSM_IO_HEADERS}
  COMMENT "Document field tables from schemas/ (x-prsm)"
  VERBATIM)
target_sources(prsm_core PRIVATE ${PRSM_IO_TABLES})
# the enums a schema's "constants" generate are part of the headers of src/io (io/dynamics_json.h
# includes prsm_io_enums.h): the code that includes those sees the generated directory too
target_include_directories(prsm_core PUBLIC ${PROJECT_BINARY_DIR}/generated)
