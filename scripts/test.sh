#!/usr/bin/env bash
# Installs what is missing, builds, and runs the tests under ctest.
# Usage: bash scripts/test.sh [--debug | --sanitize | --tsan | --fuzz]
#   (none)      the Release build in build/ with MPI (Open MPI is installed for it), every test,
#               the MPI ones (Mpi.*: mpirun -np 1, 2, 3 on this machine) included
#   --debug     the Debug build (-O0, assertions on, MPI off) in build-debug/, every test but the heavy
#               statistical and brute-force ones, which at -O0 run 10-30x their Release time
#               (the chi-square tests, the image and furnace tests, brute-force accelerator
#               comparisons): they check numbers, which Release and ASan already cover, where a
#               Debug run is for assertions and code that -O3 could hide. CANDELA_DEBUG_EXCLUDE=REGEX
#               replaces the regex (an empty value runs everything). See docs/reliability.md.
#   --sanitize  the ASan+UBSan build in build-asan/ (MPI off: Open MPI's own leaks are not ours),
#               every test but the 22 longest statistical and brute-force ones (10-40 s each in
#               Release, 5-7x that instrumented), each repeating with more samples code that a
#               lighter test of the same family runs instrumented, and the 14 power controls
#               (list and reasons in docs/reliability.md). CANDELA_ASAN_EXCLUDE=REGEX replaces the list (an empty
#               value runs everything).
#   --tsan      a ThreadSanitizer build in build-tsan/, the render session and the viewer's use of it
#               without a window (Session.*, ViewerFrontEnd.*, SceneSplit.*), with
#               OMP_THREAD_LIMIT=1 and tests/tsan.supp: GCC's libgomp is not instrumented, so TSan
#               cannot see its barriers; one OpenMP thread per pass leaves TSan the session's own
#               threads (worker and front end) to check. See docs/reliability.md.
#   --fuzz      the libFuzzer targets (tests/fuzz/, clang-14, ASan+UBSan) built in build-fuzz/ and
#               each run for CANDELA_FUZZ_SECONDS (default 5) by scripts/fuzz.sh: a check that they
#               compile and run, not a fuzzing campaign (that is `bash scripts/fuzz.sh 300`)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
mode=${1:-}
if [ -z "$mode" ]; then bash scripts/setup.sh --with-mpi; else bash scripts/setup.sh; fi
case "$mode" in
  "")
    dir=$(bash scripts/build.sh --mpi | tail -n 1)
    cd "$dir"
    ctest --output-on-failure -j"$(nproc)" --timeout 600
    ;;
  --debug)
    dir=$(bash scripts/build.sh --debug | tail -n 1)
    cd "$dir"
    # CMake's regular expressions allow at most 9 parenthesised groups in one -E: a tenth makes the
    # expression invalid and ctest then runs every test (it does not say so). Write alternatives
    # flat, not in a new group. The --sanitize regexes below share the same limit.
    heavy='^(PublicScenes/Matrix|BsdfChi2|PrincipledChi2|DiffuseBsdf\.ChiSquare|Warp\.ChiSquare|KdTree|AccelDegenerate|ImageCornell|Furnace|BsdfScenes|Mis|Stability|SelfIntersection\.BunnyNeverHitsItself|PrincipledMitsuba\.AlbedoAgrees|Cameras\.[A-Za-z]*MatchesMitsubaReference|Ptracer\.(Furnace|AgreesWithPathOnTheCornellBox|AgreesWithMitsubaPtracer|AgreesWithBsdfSampling|FilteredSplats)|Filters\.EachFilterMatchesMitsuba|BsdfWeights\.RoughPlasticWeightIsBounded|SceneSplit\.TheCoatCacheKeepsOnlyTablesInUse|BsdfFurnace|MeshFormatsRender|Microfacet\.VisibleNormal|Emitters\.MitsubaAgreement|Instancing\.(MemoryGrows|HitsAgree|MitsubaAgreement)|BsdfWrappers\.(BlendSampling|MitsubaAgreement|BlendWithDeltaLeaf|SunThroughMask)|BsdfMitsuba\.[A-Za-z]*Render|PrincipledMitsuba\.RenderAgreement|AnalyticShapes\.MitsubaAgreement|Texture\.MitsubaAgreement|Envmap\.(ImageMatchesMitsuba|SampleLiMatchesPdfLi)|Direct\.(ExactIrradiance|MatchesMitsuba)|Adaptive\.CornellImage|Bdpt\.(AgreesWith|Furnace|Unweighted|FilteredSplats)|Mlt\.(AgreesWith|BootstrapMatches|MmltAgreesWith|MmltBootstrapMatches|MmltDepthEstimates|MmltBrightness)|Ptracer\.AgreesWithPathThroughAThinLens|Denoise\.CornellDenoised16BeatsRaw256|Volpath\.MatchesMitsuba|Volpath\.WhiteFurnace|Volpath\.SingleScattering|Volpathmis\.MatchesMitsuba|Volpathmis\.WhiteFurnace|MediaPhase|MediaGrid\.DeltaAndRatio)\.?'
    exclude=${CANDELA_DEBUG_EXCLUDE-$heavy}
    ctest --output-on-failure -j"$(nproc)" --timeout 1800 ${exclude:+-E "$exclude"}
    ;;
  --sanitize)
    dir=$(bash scripts/build.sh --sanitize | tail -n 1)
    cd "$dir"
    # Leaks are errors; any sanitizer report fails the test (and shows its stack).
    export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1}
    export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
    export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/../tests/lsan.supp:print_suppressions=0}  # Mesa's own leaks
    # The viewer window test leaks inside Mesa's GL driver, which is unloaded (dlclose) before
    # LeakSanitizer runs, so no suppression can name it: it runs with leak checking off (memory
    # errors and UB are still fatal).
    viewer='^ViewerWindow\.'
    long='^(PublicScenes/Matrix|Mis\.|BsdfChi2\.SamplingMatchesPdf$|PrincipledChi2\.SamplingMatchesPdf$|KdTree\.(DragonMatchesBruteForce|BunnyMatchesBruteForce|CoherentOriginsMatchBruteForce)$|Filters\.EachFilterMatchesMitsuba$|BsdfWeights\.RoughPlasticWeightIsBounded$|PrincipledMitsuba\.AlbedoAgrees$|Ptracer\.(Furnace|AgreesWithPathOnTheCornellBox|AgreesWithMitsubaPtracerOnTheCausticsScene|AgreesWithMitsubaPtracerOnTheMirrorGlassBox|FilteredSplatsAgreeWithPathAtSharpEdges)$|Bdpt\.AgreesWithMitsubaOnTheCausticsScene|Furnace\.EverySampler$|ImageCornell\.EverySamplerMatchesMitsubaReference$|Cameras\.(Perspective|Orthographic)MatchesMitsubaReference$|Mlt\.(AgreesWithPathOnTheMirrorGlassBox|MmltAgreesWithPathOnTheCornellBox|MmltAgreesWithBdptOnTheMirrorGlassBox|MmltBrightnessSpreadMatchesItsError|MmltBrightnessConvergesWithTheMutations)$|Bdpt\.FilteredSplatsAgreeWithPathAtSharpEdges$|Denoise\.CornellDenoised16BeatsRaw256$|Volpath\.MatchesMitsuba(OnMediaSpheres|OnAHeterogeneousMedium)$|Volpathmis\.MatchesMitsuba(OnMediaSpheres|OnAHeterogeneousMedium)$)'
    # The power controls (the same agreement render with a deliberately wrong parameter, which
    # must fail) prove a statistic's power, not memory safety: they run in Release only.
    controls='^(AnalyticShapes\.MitsubaAgreementDetects|BsdfMitsuba\.[A-Za-z]*Detects|BsdfScenes\.LosslessFurnaceRejects|BsdfWrappers\.(MitsubaAgreement|BlendWithDeltaLeaf|SunThroughMask)Detects|Filters\.BoxImageIsRejected|Furnace\.DetectsBias|ImageCornell\.[A-Za-z]*Detects|Instancing\.MitsubaAgreementDetects|MeshFormatsRender\.ControlsFail|PrincipledMitsuba\.RenderAgreementDetects|Stability\.ScaleComparisonDetects|Texture\.MitsubaAgreementDetects)'
    exclude=${CANDELA_ASAN_EXCLUDE-$long|$controls}
    ctest --output-on-failure -j"$(nproc)" --timeout 1800 -E "${exclude:+$exclude|}$viewer"
    ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0" ctest --output-on-failure --timeout 1800 -R "$viewer"
    ;;
  --tsan)
    if [ ! -f build-tsan/build.ninja ]; then
      cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCANDELA_VIEWER=OFF -DCANDELA_BENCH=OFF -DCANDELA_MPI=OFF \
        -DCANDELA_TEST_FILES="test_session.cpp;test_viewer_front_end.cpp;test_scene_split.cpp" \
        -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" >/dev/null
    fi
    cmake --build build-tsan -j"$(nproc)" --target candela_tests >&2
    export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$PWD/tests/tsan.supp"
    OMP_THREAD_LIMIT=1 build-tsan/tests/candela_tests --gtest_filter='Session.*:ViewerFrontEnd.*:SceneSplit.*'
    ;;
  --fuzz)
    bash scripts/fuzz.sh "${CANDELA_FUZZ_SECONDS:-5}"
    ;;
  *) echo "test.sh: unknown option '$mode'" >&2; exit 2 ;;
esac
