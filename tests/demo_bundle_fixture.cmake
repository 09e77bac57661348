# Included by ctest after gtest_discover_tests has added the demo tests: the golden replays
# need the demo level's bake (DemoBundle.BakePreview) first.
set_tests_properties(GoldenImages.ReplayedSessionFramesMatchTheGoldens PROPERTIES FIXTURES_REQUIRED demo_bundle)
set_tests_properties(GoldenImages.NoBounceThroughTheCrateRoomsWall PROPERTIES FIXTURES_REQUIRED demo_bundle)
