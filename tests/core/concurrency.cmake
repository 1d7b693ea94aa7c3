# The core's threaded parts (the Renderer's workers and commit channels, the frame pipeline, the host
# thread pool, the short soak) as one ctest labelled `concurrency`, which the `tsan` test preset runs
# under ThreadSanitizer.
if(TARGET cohort_core_tests)
  add_test(NAME core.concurrency
           COMMAND cohort_core_tests --gtest_filter=HostThreads.*:Renderer.*:FrameTimeline.*:FramePipeline.*:FramesInFlight.*:Soak.*)
  set_tests_properties(core.concurrency PROPERTIES LABELS "core;concurrency" TIMEOUT 600)
endif()
