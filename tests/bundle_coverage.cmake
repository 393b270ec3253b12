# A bundle's files' filters (FILTERS, '|'-separated --gtest_filter patterns) select disjoint,
# non-empty sets of the bundle's cases whose sizes add up to its whole list: every case runs in
# exactly one CTest test. Run by CTest as test_bundle_<layer>_coverage.
function(count_cases filter out)
  if(filter STREQUAL "")
    execute_process(COMMAND ${BUNDLE} --gtest_list_tests RESULT_VARIABLE rc OUTPUT_VARIABLE listing ERROR_VARIABLE err)
  else()
    execute_process(COMMAND ${BUNDLE} --gtest_list_tests --gtest_filter=${filter}
                    RESULT_VARIABLE rc OUTPUT_VARIABLE listing ERROR_VARIABLE err)
  endif()
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${BUNDLE} --gtest_list_tests failed (${rc}):\n${err}")
  endif()
  # case lines are indented by two spaces under their suite's line
  string(REGEX MATCHALL "\n  [^\n]+" cases "\n${listing}")
  list(LENGTH cases n)
  set(${out} ${n} PARENT_SCOPE)
endfunction()

count_cases("" total)
string(REPLACE "|" ";" filters "${FILTERS}")
set(sum 0)
foreach(f IN LISTS filters)
  count_cases("${f}" n)
  if(n EQUAL 0)
    message(FATAL_ERROR "${BUNDLE}: the filter ${f} selects no case")
  endif()
  math(EXPR sum "${sum} + ${n}")
endforeach()
if(NOT sum EQUAL total)
  message(FATAL_ERROR "${BUNDLE}: the files' filters select ${sum} cases in all, the bundle has ${total} "
                      "(a case outside every file's suites, or in two)")
endif()
message(STATUS "${BUNDLE}: ${total} cases, each in one file's filter")
