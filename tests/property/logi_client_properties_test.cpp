// The LOGI reference client against the mock LOGI car in virtual time:
// random operator sessions of 60 s under random car misbehaviour and link
// faults, one named property per rule of the LOGI documentation's sections
// 5 and 9 and per line of its section 10 checklist (docs/dod.md).

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "tests/property/logi_rig.hpp"

namespace hil::client::logi::prop {
namespace {

#define HIL_LOGI_PROP(name, prop)                 \
  RC_GTEST_PROP(LogiClientProperties, name, ()) { \
    run_property(Prop::prop);                     \
  }

// ---- sections 5 and 9: the rules ----
HIL_LOGI_PROP(ReconnectDelaysAre1s2s3sThen3s, backoff_delays)
HIL_LOGI_PROP(OneCommandAwaitsFeedbackAtATime, single_outbound_queue)
HIL_LOGI_PROP(FeedbackTimeoutIsExactly800ms, feedback_timeout_800ms)
HIL_LOGI_PROP(OnlySpMdMvStopAreRetriedAtMostTwice, retry_rules)
HIL_LOGI_PROP(ReleaseSendsMvStop, stop_on_release)
HIL_LOGI_PROP(StaleJustAfter2sWithoutStatAndClearedOnlyByStat, stale_after_2s)
HIL_LOGI_PROP(EmergencyStopSendsMvStopFirstThenStStopInAuto, emergency_stop_order)
HIL_LOGI_PROP(EmergencyStStopResentEvery800msUntilTheCarAnswers, estop_st_stop_resent)
// End to end: at the first 800 ms slot of an emergency stop that the faults
// let through, its ST:STOP reaches the car, which runs no more and rests
// within kBrakeBound (520 ms).
HIL_LOGI_PROP(CarStopsOnceTheLinkLetsAnEmergencyStStopThrough, car_rests_after_estop)
HIL_LOGI_PROP(ATimedOutMoveIsFollowedByMvStopAtOnce, move_timeout_stops)
HIL_LOGI_PROP(FbMv0GivesANoticeMdManAndOneRetry, mode_conflict)
HIL_LOGI_PROP(SafeStateOnLossAndReconfirmAfterReconnect, safe_state_and_reconfirm)
HIL_LOGI_PROP(BadChecksumFramesAreDroppedLoggedAndTheLinkKept, bad_checksum_dropped)
HIL_LOGI_PROP(StickyAndSplitStreamsGiveEveryFrame, stream_gives_every_frame)
// End to end, from the physics (logi_rig.hpp, kBrakeBound and kStopToRest):
// top speed 0.5 m/s braked at 1 m/s^2 rests in 500 ms (+ two 1/120 s
// steps: 520 ms after a stop reaches the car); a stop written at once is
// attempted at 0, 800 and 1600 ms, so whenever one attempt the car acts on
// gets through (in AUTO: ST:STOP) the chassis is at rest 2120 ms after the
// release or emergency stop.
HIL_LOGI_PROP(ChassisRestsWithin2120msOfAStopThatGetsThrough, chassis_rests_after_stop)

// ---- section 10: the checklist ----
HIL_LOGI_PROP(ConnectAndDisconnectByHand, connect_disconnect)
HIL_LOGI_PROP(StatusAndFeedbackParsedAndMatched, status_and_feedback_parsed)
HIL_LOGI_PROP(EveryControlSendsItsExactFrame, buttons_send_exact_frames)
HIL_LOGI_PROP(ManualControlDrivesEveryDirection, manual_directions)
HIL_LOGI_PROP(AutoFlowStationRunStop, auto_flow)
HIL_LOGI_PROP(ReconnectsWithoutTheOperator, reconnects_automatically)
HIL_LOGI_PROP(LogHoldsTxRxAndParseErrors, log_has_tx_rx_errors)
HIL_LOGI_PROP(TelemetryShownIsTheLastStat, telemetry_visible)
HIL_LOGI_PROP(ModeAndHeldDirectionShown, mode_and_direction_shown)
HIL_LOGI_PROP(EmergencyStopAlwaysAccessible, emergency_stop_accessible)
HIL_LOGI_PROP(EveryFrameWrittenHasItsRightChecksum, checksums_built_right)

}  // namespace
}  // namespace hil::client::logi::prop
