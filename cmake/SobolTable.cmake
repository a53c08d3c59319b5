# SobolTable.cmake: the Joe-Kuo Sobol direction numbers (new-joe-kuo-6.21201) of src/mc/sobol.c.
#
# Included by the top-level CMakeLists.txt after prsm_core is defined. The table is not kept in
# git: scripts/gen-sobol-table.py reads it from Debian's python3-scipy
# (scipy/stats/_sobol_direction_numbers.npz), checks it and writes
# <build>/generated/prsm_sobol_table.c at build time, regenerated when the script or the .npz
# changes, and compiled into prsm_core. Needs /usr/bin/python3 with python3-scipy and
# python3-numpy (scripts/install-deps.sh); PRSM_PYTHON3 names another interpreter.
set(PRSM_PYTHON3 /usr/bin/python3 CACHE FILEPATH "Python 3 with scipy, for the Sobol table")
set(PRSM_SOBOL_SCRIPT ${PROJECT_SOURCE_DIR}/scripts/gen-sobol-table.py)
set(PRSM_SOBOL_TABLE ${PROJECT_BINARY_DIR}/generated/prsm_sobol_table.c)

# Configure-time check, so a missing scipy is a clear message and not a failed build later.
execute_process(COMMAND ${PRSM_PYTHON3} ${PRSM_SOBOL_SCRIPT} --print-source
                OUTPUT_VARIABLE PRSM_SOBOL_NPZ ERROR_VARIABLE prsm_sobol_error
                RESULT_VARIABLE prsm_sobol_rc OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT prsm_sobol_rc EQUAL 0 OR NOT EXISTS "${PRSM_SOBOL_NPZ}")
  message(FATAL_ERROR "The Sobol direction numbers come from python3-scipy "
                      "(scripts/install-deps.sh installs it): ${prsm_sobol_error}")
endif()

add_custom_command(
  OUTPUT ${PRSM_SOBOL_TABLE}
  COMMAND ${PRSM_PYTHON3} ${PRSM_SOBOL_SCRIPT} --out ${PRSM_SOBOL_TABLE}
  DEPENDS ${PRSM_SOBOL_SCRIPT} ${PRSM_SOBOL_NPZ}
  COMMENT "Sobol direction numbers (Joe-Kuo new-joe-kuo-6.21201) from scipy"
  VERBATIM)
target_sources(prsm_core PRIVATE ${PRSM_SOBOL_TABLE})
