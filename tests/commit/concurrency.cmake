# The commit channel's concurrent fill/apply test, also as one ctest labelled `concurrency`, which the
# `tsan` test preset runs under ThreadSanitizer.
if(TARGET cohort_commit_tests)
  add_test(NAME commit.concurrency COMMAND cohort_commit_tests --gtest_filter=CommitChannelConcurrency.*:CommitChannel.*)
  set_tests_properties(commit.concurrency PROPERTIES LABELS "commit;concurrency" TIMEOUT 600)
endif()
