/*
 * railproof — level-crossing protection, the on-board-requested warning with a protection
 * pattern (D5 §5.3; spec/design/lc.md §3, §4, §6). C++: lc::onboard::CrossingProtection::Cycle
 * (cpp/runtime/lc/src/onboard/crossing_protection.cpp), lc::wayside::CrossingController::Cycle
 * (cpp/runtime/lc/src/wayside/crossing_controller.cpp). The GNSS-time pre-armed crossings of
 * D4 §4.8.2 are the second model, models/lc_gnss.pml; the parts both share (state, controller,
 * train motion, earliest arrival, checks) are in models/include/lc_shared.pml.
 *
 * What is modelled. A line of track cells 0..MODEL_TRACK (one cell = the distance run in one
 * tick at speed 1), one train of MODEL_TRAIN_LEN cells, a station stop at MODEL_STATION and
 * two crossings A and B, each one cell wide, at MODEL_LC_A and MODEL_LC_B beyond it. One tick
 * is one cycle of every unit (on-board, crossing controllers, centre), all at the same `now`.
 *
 * Train. Positions are kept in half-cells and the speed is 0..MODEL_VMAX cells per tick,
 * changing by at most 1 per tick (acceleration and braking 1 cell/tick²); in a tick the train
 * runs (v + v') / 2 cells, the exact distance under a constant acceleration, so its motion is
 * that of a real train with these limits and the continuous earliest-arrival computation of
 * design §2 is exact for it. An ETA is kept as eta2 = 2 floor(E) + (E not whole), E in ticks:
 * every comparison of the design with a whole number of ticks n is exact on it (E <= n iff
 * eta2 <= 2n, E >= n iff eta2 >= 2n), and so is the C++'s ms value rounded down (the vector
 * generator checks the tick length against every fraction that occurs). The train stops at
 * the station (it never chooses a speed from which it cannot stop there) and dwells there
 * (ONBOARD: its departure is not authorised before t_dep = arrival + DWELL; GNSS: it leaves
 * on the departure signal), may stand anywhere as long as it likes and stops at the end of
 * the track. It brakes on the protection pattern: it never chooses a speed from which it
 * cannot stop before the most restrictive protection limit (the braking module's guarantee,
 * REQ-BR-001, ASM-030); if none is left (a clearance revoked too late) it brakes as hard as it
 * can. The position envelope has no error (front_max = front, rear_min = front - length).
 * The train occupies a crossing from front >= near until rear >= far; the properties check
 * the crossing's state during every tick the train occupies it or enters it.
 *
 * ONBOARD configuration (the default; design §3, §4). Per crossing the on-board function
 * (APPROACHING, REQUESTED, CLEARED, PASSED, DONE, in the order of CrossingProtection::Cycle:
 * passage, request at ETA <= W + LEAD (a train standing in its dwell: the remaining dwell plus
 * the run from rest), clearance on a report of the cycle (age <= CMA) that is CLOSED, lists the
 * train among the requesters and has ws + W <= now + ETA, revocation on any other report,
 * protection limit near - PO for APPROACHING and REQUESTED, withdrawal until acknowledged)
 * and a controller (OPEN, WARNING, CLOSING, CLOSED, OPENING, FAILED, in the order of
 * CrossingController::Cycle). A tick runs the controllers' cycles, then the on-board cycle.
 * The radio: every telegram (request or withdrawal per crossing, train -> ground; the report
 * with the withdrawal acknowledgement per crossing, ground -> train, every cycle) arrives in
 * its tick, one tick late (delay MODEL_MAX_DELAY) or is lost; the telegrams of a link arrive
 * in order (the telegram layer, REQ-TG-004). A train telegram of tick k reaches the
 * controllers' cycle of tick k + 1 or k + 2; a report of the controllers' cycle of tick k
 * reaches the on-board cycle of tick k (age 0) or k + 1 (age 1). The barriers, detected down
 * or up every cycle, may never come down (stuck up), lose their down detection while closed,
 * or never rise again (stuck down).
 *
 * The requester list. The report names the trains among the controller's requesters, and the
 * train is cleared only by a CLOSED report that names it (and revoked by one that does not):
 * design §3 item 3, CrossingReport::requesters. The earlier rule (any CLOSED report clears)
 * lets a train whose requests are lost or late be cleared by a warning held for another
 * train, which ends when that train withdraws while the first one runs onto the crossing
 * (mutant MUTANT_CLEAR_ON_ANY_CLOSED, rejected by REQ_LC_003_occupancy in TWO_TRAINS).
 *
 * Configurations (-D; each property names those it is verified in): ONBOARD (= default);
 * LONG_WARNING = ONBOARD with crossings whose design warning time is one tick longer (with
 * W = MODEL_WARN_TICKS, MODEL_LOWER_TICKS = 1 and the protection offset, the first CLOSED
 * report can only reach a train that is at least W - LOWER - 1 ticks away, so the clearance's
 * warning-time condition never decides: LONG_WARNING makes it decide); TWO_TRAINS = ONBOARD
 * with a second train (another track) requesting and withdrawing crossing A at any time,
 * working barriers; FAIR = ONBOARD with working barriers (down and up within the timeout), no
 * second train and a fair radio (a link never loses two telegrams in a row): the bounded
 * response of the warning's end; HEALTHY = ONBOARD with prompt barriers, no loss and reports
 * within the confirmation age (REQ-LC-015); WALK stops after MODEL_CYCLES ticks (random
 * walks); TRAPS adds the goal flags.
 *
 * Timing (ticks; spec/parameters/lc.yaml model_bounds and the model-local bounds
 * below): W = MODEL_WARN_TICKS design warning time, LOWER = MODEL_LOWER_TICKS barrier
 * lowering, TO = W - LOWER barrier timeout (a crossing is CLOSED or FAILED once the warning
 * time is over, as ASM-029's 8 s + 15 s <= 30 s), LEAD request lead (the smallest that keeps
 * REQ_LC_015), CMA = 0 confirmation age (a report of the on-board cycle's own tick), PO
 * protection offset (cells), RESP bounded response (the smallest that keeps REQ_LC_007_ends).
 *
 * Properties are evaluated in the cycles and after every tick on the state before it, the
 * inputs, the outputs and the state after it, into latched ghost bits v_*; each LTL property
 * says one of them never becomes 1. Inputs, outputs and scratch values are cleared as soon as
 * they are consumed, every nondeterministic choice is one transition (the breadth-first
 * search stores the states inside the atomic tick). The ONBOARD configurations keep times
 * relative (warning age, timers) and are exhaustive over unbounded runs.
 *
 * Annotations read by testgen: see models/tg.pml.
 */

#include "lc_shared.pml"

/* ======================================================================================= *
 * ONBOARD                                                                                 *
 * ======================================================================================= */

/* ---- on-board crossing function (design §3, CrossingProtection::Cycle) ---------------------- */
#ifdef MUTANT_WITHDRAW_AT_FRONT
#define PASSED(i) (x >= FAR(i))            /* the front, not the rear, beyond the far edge */
#else
#define PASSED(i) (x >= FAR(i) + L2)       /* rear_min >= far */
#endif
#ifdef MUTANT_REQUEST_LATE
#define REQ_AT (2 * (W + LEAD) - 1)
#else
#define REQ_AT (2 * (W + LEAD))
#endif
#ifdef MUTANT_NO_DWELL
#define DWELL_OF 0
#else
#define DWELL_OF (ph == P_DWELL -> dw : 0)
#endif
#ifdef MUTANT_STALE_CONFIRMATION
#define FRESH(age) true
#else
#define FRESH(age) ((age) <= CMA)
#endif
#ifdef MUTANT_CLEAR_WITHOUT_WARNING_TIME
#define WARNED_ENOUGH(i, wnow) true
#else
#define WARNED_ENOUGH(i, wnow) (2 * (wnow) + eta[i] >= 2 * W)
#endif
/* the report lists the train among the requesters (the confirmation is for this train) */
#ifdef MUTANT_CLEAR_ON_ANY_CLOSED
#define LISTED(rr) true
#else
#define LISTED(rr) (rr)
#endif
#define REVOKES(r, rr) (r != 1 + R_CLOSED || !LISTED(rr))

/* step 3 for one report r (status + 1, 0 none), requester bit rr, age `age`, warning age now
 * `wnow` */
inline take_report(i, r, rr, age, wnow) {
  if
  :: r != 0 && ob[i] == O_REQ && r == 1 + R_CLOSED && LISTED(rr) && FRESH(age) && WARNED_ENOUGH(i, wnow) ->
     ob[i] = O_CLR
  :: r != 0 && ob[i] == O_CLR && REVOKES(r, rr) -> ob[i] = O_REQ
  :: else -> skip
  fi
}

/* The report of crossing i issued by the controllers' cycle of the last tick (its content is
 * the controller's state now: no cycle ran since) and the delayed one of the tick before. */
#ifdef HEALTHY
#define CAN_DELAY_DL false          /* reports within the confirmation age */
#else
#define CAN_DELAY_DL (DMAX >= 1)
#endif
#ifdef MUTANT_STALE_CONFIRMATION
#define KEEP_DOWA(i) dowa[i] = wa[i]
#define CLEAR_DOWA(i) dowa[i] = 0
#else
#define KEEP_DOWA(i) skip
#define CLEAR_DOWA(i) skip
#endif
inline downlink(i) {
  r2[i] = dold[i]; r2r[i] = doreq[i]; r2a[i] = doack[i];
  if
  :: dold[i] != 0 -> printf("@IN rx c=%d age=1\n", i)
  :: else -> skip
  fi;
  dold[i] = 0; doreq[i] = 0; doack[i] = 0; CLEAR_DOWA(i);
  if
  :: fate == F_NOW -> r1[i] = 1 + STATUS(cs[i]); r1r[i] = rq[i]; r1a[i] = ackd[i]; LOST(dl_l[i], 0);
     printf("@IN rx c=%d age=0\n", i)
  :: fate == F_LATE ->
     dold[i] = 1 + STATUS(cs[i]); doreq[i] = rq[i]; doack[i] = ackd[i]; KEEP_DOWA(i); LOST(dl_l[i], 0)
  :: fate == F_LOST -> LOST(dl_l[i], 1)
  fi;
  ackd[i] = 0; fate = 0
}
#define PICK_DOWNLINK(i) PICK_FATE(CAN_DELAY_DL, CAN_LOSE(dl_l[i]))

/* the on-board cycle for crossing i (steps 0-3); the report goals and the freshness check */
inline onboard_crossing(i, k) {
  was_ob[i] = ob[i];
  if
  :: ob[i] <= O_CLR -> sd = NEAR(i) - x; c = DWELL_OF; eta_of(sd, v, c, eta[i]); c = 0
  :: else -> eta[i] = 0
  fi;
  /* 1. passage; an acknowledgement ends a withdrawal sent before this cycle */
  if :: PASSED(i) && ob[i] != O_DONE -> ob[i] = O_PAS :: else -> skip fi;
  if :: was_ob[i] == O_PAS && (r2a[i] || r1a[i]) -> ob[i] = O_DONE :: else -> skip fi;
  /* 2. request */
  if :: ob[i] == O_APP && eta[i] <= REQ_AT -> ob[i] = O_REQ :: else -> skip fi;
  mid_ob[i] = ob[i];
  /* 3. reports in reception order: the delayed one of the last cycle (age 1), then this
   * cycle's (age 0) */
#ifdef MUTANT_STALE_CONFIRMATION
  wn = MIN(dowa[i] + 1, WCAP);
#else
  wn = 0;
#endif
  take_report(i, r2[i], r2r[i], 1, wn);
  wn = wa[i];
  take_report(i, r1[i], r1r[i], 0, wn);
  /* REQ-LC-003: cleared only on this cycle's controller state (the only report within the
   * confirmation age) being CLOSED for this train with a warning start W before the arrival */
  if
  :: ob[i] == O_CLR && mid_ob[i] == O_REQ && !(cs[i] == C_CLOSED && rq[i] && 2 * wa[i] + eta[i] >= 2 * W) ->
     v_fresh = 1
  :: else -> skip
  fi;
  /* goals of the report handling (k: this crossing's goal numbers) */
  ON(mid_ob[i] == O_REQ && ob[i] == O_CLR && r1[i] == 1 + R_CLOSED && 2 * wn + eta[i] == 2 * W, k + 3);
  ON(mid_ob[i] == O_REQ && ob[i] == O_REQ && r1[i] == 1 + R_CLOSED && r1r[i] && 2 * wn + eta[i] < 2 * W, k + 4);
  ON(mid_ob[i] == O_REQ && ob[i] == O_REQ && r2[i] == 1 + R_CLOSED && r1[i] == 0 && r2r[i], k + 5);
  ON(was_ob[i] == O_CLR && ob[i] == O_REQ && (r1[i] == 1 + R_FAILED || r2[i] == 1 + R_FAILED), k + 6);
  ON(was_ob[i] == O_PAS && ob[i] == O_DONE, k + 7);
  ON(mid_ob[i] == O_REQ && ob[i] == O_REQ && r1[i] == 0 && r2[i] == 0 && cs[i] == C_CLOSED && rq[i], k + 8);
  ON((i) == 0 && mid_ob[0] == O_REQ && ob[0] == O_REQ && r1[0] == 1 + R_CLOSED && !r1r[0], 59);
  wn = 0;
  r2[i] = 0; r2r[i] = 0; r2a[i] = 0; r1[i] = 0; r1r[i] = 0; r1a[i] = 0
}

#ifdef MUTANT_NO_PROTECTION_REQUESTED
#define PROTECTS(i) (ob[i] == O_APP)
#else
#define PROTECTS(i) (ob[i] == O_APP || ob[i] == O_REQ)
#endif
/* 4. outputs: the telegram to the crossing, the protection limit */
#define MSG(i) ((ob[i] == O_REQ || ob[i] == O_CLR) -> M_REQ : (ob[i] == O_PAS -> M_WD : M_NONE))
inline onboard_outputs() {
  lim = NOLIM;
  if :: PROTECTS(1) -> lim = LIM(1) :: else -> skip fi;
  if :: PROTECTS(0) -> lim = LIM(0) :: else -> skip fi;
  c = 0;
  do
  :: c < 2 ->
     /* REQ-LC-004: a withdrawal only once the rear has passed; REQ-LC-002/-005: requested from
      * the first cycle whose (dwell-aware) ETA is within W + LEAD until the rear has passed,
      * never before (g_due: the train's own ETA, computed apart) */
     if
     :: MSG(c) == M_WD && !(x >= FAR(c) + L2) -> v_end = 1
     :: (MSG(c) == M_REQ) != (g_due[c] && !(x >= FAR(c) + L2)) -> v_req = 1
     :: else -> skip
     fi;
     c++
  :: else -> break
  od;
  c = 0
}

/* the ghost ETA of the train at the start of the tick (before the on-board cycle) */
inline ghost_due(i) {
  if
  :: x >= FAR(i) + L2 -> g_due[i] = 0
  :: x < FAR(i) + L2 && !g_due[i] -> sd = NEAR(i) - x; c = (ph == P_DWELL -> dw : 0); eta_of(sd, v, c, e_d);
     g_due[i] = (e_d <= 2 * (W + LEAD)); e_d = 0; c = 0
  :: else -> skip
  fi
}

/* The train's telegram of this tick to crossing i (after the on-board cycle) and the
 * delayed one of the last tick, in order; then the controller's step 2 for them. */
inline uplink(i) {
  u1[i] = uold[i];
  if :: uold[i] != M_NONE -> printf("@IN ul c=%d age=1 m=%d\n", i, uold[i]) :: else -> skip fi;
  uold[i] = M_NONE;
  if
  :: MSG(i) == M_NONE -> skip
  :: MSG(i) != M_NONE && fate == F_NOW -> u0[i] = MSG(i); LOST(ul_l[i], 0); printf("@IN ul c=%d age=0 m=%d\n", i, u0[i])
  :: MSG(i) != M_NONE && fate == F_LATE -> uold[i] = MSG(i); LOST(ul_l[i], 0)
  :: MSG(i) != M_NONE && fate == F_LOST -> LOST(ul_l[i], 1)
  fi;
  fate = 0
}
#define PICK_UPLINK(i) PICK_FATE(MSG(i) != M_NONE && DMAX >= 1, MSG(i) != M_NONE && CAN_LOSE(ul_l[i]))
#define PICK_UPLINK(i) PICK_FATE(MSG(i) != M_NONE && DMAX >= 1, MSG(i) != M_NONE && CAN_LOSE(ul_l[i]))

inline ctrl_messages(i) {
  ctrl_timers(i);
  /* 2. requests add their train, withdrawals remove it and are acknowledged */
  if :: u1[i] == M_REQ || u0[i] == M_REQ -> rq[i] = 1; rin[i] = 1 :: else -> skip fi;
  if
  :: u1[i] == M_WD || u0[i] == M_WD -> rq[i] = 0; ackd[i] = 1;
#if defined(MUTANT_END_WITH_REQUESTER) && defined(OTHER)
     if :: (i) == 0 -> orq = 0 :: else -> skip fi   /* every requester removed */
#else
     skip
#endif
  :: else -> skip
  fi;
  /* goals of the train's telegrams (crossing A) */
  if
  :: (i) == 0 ->
     ON(MSG(0) == M_REQ && u0[0] == M_NONE && uold[0] == M_NONE && u1[0] == M_NONE && was_cs[0] == C_OPEN && !OREQ(0), 45);
     ON(was_cs[0] == C_OPEN && u1[0] == M_REQ && u0[0] == M_NONE && !OREQ(0), 46);
     ON(ob[0] == O_PAS && u0[0] == M_NONE && u1[0] == M_NONE && was_cs[0] == C_CLOSED, 47);
     ON(was_cs[0] == C_CLOSED && u1[0] == M_WD && u0[0] == M_NONE, 48);
     ON(was_cs[0] == C_OPEN && ackd[0], 58)
  :: else -> skip
  fi;
  u1[i] = 0; u0[i] = 0
}

#ifdef OTHER
#define PICK_OTHER \
  if \
  :: oev = 0 \
  :: d_step { ost < 2 -> oev = M_REQ } \
  :: d_step { ost == 1 -> oev = M_WD } \
  fi
inline other() {
  if :: oev == M_REQ && ost == 0 -> ost = 1 :: oev == M_WD -> ost = 2 :: else -> skip fi;
  printf("@IN other ev=%d\n", oev)
}
inline other_messages() {
  if :: oev == M_REQ -> orq = 1 :: else -> skip fi;
  if :: oev == M_WD -> orq = 0 :: else -> skip fi;
#ifdef MUTANT_END_WITH_REQUESTER
  if :: oev == M_WD -> rq[0] = 0 :: else -> skip fi   /* every requester removed */
#else
  skip
#endif
}
#endif

/* the controllers' transition and its goals (k: this crossing's goal numbers) */
inline ctrl_step(i, k) {
  printf("@IN bar c=%d down=%d up=%d\n", i, down[i], up[i]);
  ctrl_transition(i);
  /* REQ-LC-007: the warning ends only with no requester left */
  if
  :: was_cs[i] == C_CLOSED && cs[i] == C_OPENING && (rq[i] || OREQ(i)) -> v_end = 1
  :: was_cs[i] == C_CLOSED && cs[i] == C_OPENING && NEEDED(i) && !(x >= FAR(i) + L2) -> v_end = 1
  :: else -> skip
  fi;
  ON(was_cs[i] == C_CLOSING && cs[i] == C_FAILED, k + 10);
  ON(was_cs[i] == C_CLOSING && cs[i] == C_CLOSED && wa[i] == LOWER + TO, k + 11);
  ON(was_cs[i] == C_CLOSED && cs[i] == C_FAILED, k + 12);
  ON(was_cs[i] == C_OPENING && cs[i] == C_OPEN, k + 13);
  ON(was_cs[i] == C_OPENING && cs[i] == C_FAILED, k + 14);
  ON(was_cs[i] == C_CLOSED && cs[i] == C_OPENING, k + 15);
  ON(was_cs[i] == C_CLOSING && cs[i] == C_CLOSED && wa[i] == LOWER + 1, k + 16);
#ifdef OTHER
  if
  :: (i) == 0 ->
     ON(was_cs[0] == C_CLOSED && cs[0] == C_CLOSED && orq && ackd[0], 52);
     ON(was_cs[0] == C_OPENING && cs[0] == C_WARN, 53);
     ON(was_cs[0] == C_CLOSED && cs[0] == C_OPENING && oev == M_WD, 54);
     ON(was_cs[0] == C_OPEN && wsn[0] && oev == M_REQ && ob[0] == O_APP, 55)
  :: else -> skip
  fi;
#endif
  down[i] = 0; up[i] = 0; rin[i] = 0
}

/* ---- properties (ONBOARD) and goals, after the tick ------------------------------------------- */
inline check() {
  check_common(0);
  check_common(1);
  /* REQ-LC-015: the protection never takes away a speed the train could otherwise choose */
  if :: hi < hif -> v_brake = 1 :: else -> skip fi
}

inline goals_crossing(i, k) {
  ON(was_ob[i] == O_APP && ob[i] != O_APP && eta[i] == 2 * (W + LEAD), k + 0);
  ON(was_ob[i] == O_APP && ob[i] == O_APP && eta[i] == 2 * (W + LEAD) + 2, k + 1);
  ON(was_ob[i] == O_APP && ob[i] != O_APP && eta[i] == 2 * (W + LEAD) && was_ph == P_DWELL && was_dw > 0, k + 2);
  ON(was_ob[i] == O_CLR && ob[i] == O_PAS && was_x == FAR(i) + L2, k + 17);
  ON(ob[i] == O_CLR && was_x < FAR(i) + L2 && was_x >= FAR(i), k + 18);
  ON(OCC(i) && was_x == NEAR(i) && was_wa[i] + 1 == W, k + 19)
}

/* per crossing goals: crossing A = 0..19, crossing B = 20..39 (same meaning) */
inline goals() {
  goals_crossing(0, 0);
  goals_crossing(1, 20);
  /* REQ-LC-005: standing in the dwell, ETA counted from the departure: no request yet */
  ON(was_ph == P_DWELL && was_dw > 0 && was_ob[0] == O_APP && ob[0] == O_APP &&
     eta[0] > 2 * (W + LEAD) && eta[0] - 2 * was_dw <= 2 * (W + LEAD), 40);
  /* REQ-LC-003: the train stands exactly at the protection limit of a crossing not cleared */
  ON(x == LIM(0) && v == 0 && (ob[0] == O_REQ || ob[0] == O_APP), 41);
  /* REQ-LC-003: the protection makes the train brake (no confirmation in time) */
  ON(hi < hif, 42);
  /* REQ-LC-006: both crossings warning at once; REQ-LC-003: both cleared at once */
  ON(WARNING(cs[0]) && WARNING(cs[1]) && cs[0] != C_FAILED && cs[1] != C_FAILED, 43);
  ON(ob[0] == O_CLR && ob[1] == O_CLR, 44);
  /* REQ-LC-005: departure after the dwell with the first crossing cleared / not yet cleared */
  ON(was_ph == P_DWELL && ph == P_GONE && ob[0] == O_CLR, 49);
  ON(was_ph == P_DWELL && ph == P_GONE && ob[0] == O_REQ, 50);
  /* REQ-LC-004 REQ-LC-007: both crossings passed and withdrawn (DONE) */
  ON(ob[0] == O_DONE && ob[1] == O_DONE, 51);
  /* REQ-LC-003 REQ-LC-014: the train on a crossing whose barriers failed under it */
  ON(OCC(0) && cs[0] == C_FAILED, 56);
  /* REQ-LC-005: the train arrives at the station and dwells */
  ON(was_ph == P_BEFORE && ph == P_DWELL, 57);
  /* REQ-LC-004: a repeated withdrawal is acknowledged again (the first acknowledgement lost) */
  skip
}

inline clear_tick() {
  eta[0] = 0; eta[1] = 0; oev = 0; wsn[0] = 0; wsn[1] = 0;
  lim = 0; lo = 0; hi = 0; hif = 0; nv = 0;
  was_x = 0; was_v = 0; was_ph = 0; was_dw = 0; was_cs[0] = 0; was_cs[1] = 0; was_wa[0] = 0;
  was_wa[1] = 0; was_ob[0] = 0; was_ob[1] = 0; mid_ob[0] = 0; mid_ob[1] = 0; c = 0; wn = 0; sd = 0;
  /* canonical values where they are not read */
  if :: cs[0] == C_OPEN || cs[0] == C_OPENING -> wa[0] = 0 :: else -> skip fi;
  if :: cs[1] == C_OPEN || cs[1] == C_OPENING -> wa[1] = 0 :: else -> skip fi;
  if :: cs[0] != C_OPENING -> tm[0] = 0 :: else -> skip fi;
  if :: cs[1] != C_OPENING -> tm[1] = 0 :: else -> skip fi
}

init {
  /* the train starts at the line's start, or standing at the station at the start of its dwell */
  if
  :: d_step { x = 0; ph = P_BEFORE }
  :: d_step { x = STA; ph = P_DWELL; dw = DWELL }
  fi;
  do
  :: atomic {
#ifdef WALK
       ncycles < MODEL_CYCLES -> ncycles++;
#endif
       CLEAR_GOALS;
       /* 1. the train's telegrams of the last tick, the second train, the barriers; the
        *    controllers' cycles */
       PICK_UPLINK(0);
       d_step { printf("@IN tick x=%d v=%d ph=%d dw=%d\n", x, v, ph, dw); uplink(0); ctrl_messages(0) };
       PICK_UPLINK(1);
       d_step { uplink(1); ctrl_messages(1) };
#ifdef OTHER
       PICK_OTHER;
       d_step { other(); other_messages() };
#endif
       PICK_BARRIER(0);
       d_step { barrier(0); ctrl_step(0, 0) };
       PICK_BARRIER(1);
       d_step {
         barrier(1); ctrl_step(1, 20);
         printf("@OUT ctrl c=0 cs=%d wa=%d new=%d ack=%d rq=%d\n", cs[0], wa[0], wsn[0], ackd[0], rq[0]);
         printf("@OUT ctrl c=1 cs=%d wa=%d new=%d ack=%d rq=%d\n", cs[1], wa[1], wsn[1], ackd[1], rq[1])
       };
       /* 2. this cycle's reports (and last tick's delayed ones) to the on-board unit, its cycle */
       PICK_DOWNLINK(0);
       d_step { ghost_due(0); ghost_due(1); downlink(0); onboard_crossing(0, 0) };
       PICK_DOWNLINK(1);
       d_step {
         downlink(1); onboard_crossing(1, 20);
         onboard_outputs();
         printf("@OUT board s0=%d s1=%d e0=%d e1=%d lim=%d\n", ob[0], ob[1], eta[0], eta[1], lim);
         motion_bounds()
       };
       /* 3. the train's speed for the tick */
       PICK_SPEED;
       d_step {
         move();
         printf("@OUT move x=%d v=%d\n", x, v);
         check();
         goals();
         clear_tick()
       }
     }
  od
}


// @property REQ_LC_003_occupancy REQ-LC-003 REQ-LC-006 REQ-LC-011 REQ-LC-014 : the train never occupies a crossing (front at or beyond the near edge, rear before the far edge, also inside a tick) unless it has warned for at least MODEL_WARN_TICKS at the train's arrival and is CLOSED; ONBOARD: or its barriers lost their down detection while the train was cleared (a detected failure under a cleared train); GNSS: or it FAILED (no train-side protection: the lights keep warning) [config ONBOARD LONG_WARNING TWO_TRAINS FAIR HEALTHY]
ltl REQ_LC_003_occupancy { [] !v_occ }
// @property REQ_LC_003_fresh REQ-LC-003 REQ-LC-001 : the on-board unit clears a crossing only on the controller's state of the same cycle (the only report within the confirmation age) being CLOSED with the train among its requesters and a warning start at least MODEL_WARN_TICKS before the train's earliest arrival [config ONBOARD LONG_WARNING TWO_TRAINS FAIR HEALTHY]
ltl REQ_LC_003_fresh { [] !v_fresh }
// @property REQ_LC_007_end REQ-LC-004 REQ-LC-007 REQ-LC-012 : a withdrawal (ONBOARD) or warning stop (GNSS) is sent only after the train's rear has passed the crossing's far edge, and a warning ends (CLOSED to OPENING) only when no requester is left and the train that needed it has passed with its rear [config ONBOARD LONG_WARNING TWO_TRAINS FAIR HEALTHY]
ltl REQ_LC_007_end { [] !v_end }
// @property REQ_LC_007_ends REQ-LC-007 REQ-LC-004 REQ-LC-012 : with a working crossing and a fair radio (no link loses two telegrams in a row) the warning of a crossing ends (OPEN) at most MODEL_RESPONSE_TICKS ticks after the train's rear passed it (bounded response: the liveness of design §6 under weak fairness, as a safety property) [config FAIR HEALTHY]
ltl REQ_LC_007_ends { [] !v_live }
// @property REQ_LC_002_request REQ-LC-002 REQ-LC-005 REQ-LC-001 : the request of a crossing is sent in every cycle from the first whose earliest arrival (for a train standing in its dwell: the remaining dwell plus the run from rest) is within the warning time plus the lead, until the rear has passed, and never before [config ONBOARD LONG_WARNING TWO_TRAINS FAIR HEALTHY]
ltl REQ_LC_002_request { [] !v_req }
// @property REQ_LC_006_controller REQ-LC-006 : a controller starts the warning in the cycle a request arrives (GNSS: its stored start time is reached or its clock is faulty), commands the barriers down MODEL_LOWER_TICKS later, is CLOSED only while the barriers are detected down, fails when they are not down by the barrier timeout, and a failed crossing stays failed [config ONBOARD LONG_WARNING TWO_TRAINS]
ltl REQ_LC_006_controller { [] !v_ctrl }
// @property REQ_LC_015_no_braking REQ-LC-015 : with a working crossing and reports within the confirmation age, the protection pattern never takes away a speed the train could otherwise choose (it never makes the train brake or hold back) [config HEALTHY]
ltl REQ_LC_015_no_braking { [] !v_brake }

// ---- mutants: one per seeded C++ fault (same meaning), then further ones -------------------------
// @mutant MUTANT_CLEAR_WITHOUT_WARNING_TIME violates REQ_LC_003_occupancy : the clearance ignores ws + W <= now + ETA (C++ FAULT_LC_CLEAR_WITHOUT_WARNING_TIME) [config LONG_WARNING]
// @mutant MUTANT_WITHDRAW_AT_FRONT violates REQ_LC_007_end : the withdrawal is sent once the front (not the rear) passed the far edge (C++ FAULT_LC_WITHDRAW_AT_FRONT) [config ONBOARD]
// @mutant MUTANT_STALE_CONFIRMATION violates REQ_LC_003_fresh : the age of a CLOSED confirmation is not checked (C++ FAULT_LC_STALE_CONFIRMATION) [config ONBOARD]
// @mutant MUTANT_END_WITH_REQUESTER violates REQ_LC_007_end : a withdrawal removes every requester, so the warning ends when one of two requesters withdrew (C++ FAULT_LC_END_WITH_REQUESTER) [config TWO_TRAINS]
// @mutant MUTANT_CLEAR_ON_ANY_CLOSED violates REQ_LC_003_occupancy : a CLOSED report clears the train although it does not list the train among the requesters (a crossing closed for another train; the earlier rule of design §3; C++ FAULT_LC_CLEAR_ON_ANY_CLOSED) [config TWO_TRAINS]
// @mutant MUTANT_REQUEST_LATE violates REQ_LC_002_request : the request only half a tick after the ETA reached W + LEAD [config ONBOARD]
// @mutant MUTANT_NO_DWELL violates REQ_LC_002_request : the ETA of a train standing in its dwell ignores the remaining dwell (request too early) [config ONBOARD]
// @mutant MUTANT_NO_PROTECTION_REQUESTED violates REQ_LC_003_occupancy : a REQUESTED crossing gives no protection limit [config ONBOARD]
// @mutant MUTANT_LOWER_LATE violates REQ_LC_006_controller : the barriers are commanded down one tick late [config ONBOARD]
// @mutant MUTANT_CLOSED_WITHOUT_DOWN violates REQ_LC_006_controller : the barrier timeout gives CLOSED instead of FAILED [config ONBOARD]

// ---- coverage goals (trap properties) -------------------------------------------------------------
// ONBOARD, per crossing: A = 0..19, B = 20..39 (same meaning)
// @goal 0 REQ-LC-002 REQ-LC-001 : boundary: crossing A requested at exactly ETA = W + LEAD
// @goal 1 REQ-LC-002 REQ-LC-005 : boundary: crossing A not requested at ETA one tick above W + LEAD (no ETA of the geometry lies strictly between)
// @goal 2 REQ-LC-005 : boundary: crossing A requested in the dwell at exactly remaining dwell + ETA from rest = W + LEAD
// @goal 3 REQ-LC-003 : boundary: crossing A cleared with the warning time exactly sufficient (ws + W = now + ETA)
// @goal 4 REQ-LC-003 : crossing A not cleared: CLOSED for the train but warned too short for its ETA [config LONG_WARNING]
// @goal 5 REQ-LC-003 REQ-LC-014 : boundary: crossing A not cleared on a CLOSED report one tick older than the confirmation age (delayed, no fresh report)
// @goal 6 REQ-LC-003 REQ-LC-014 : crossing A's clearance revoked by a FAILED report
// @goal 7 REQ-LC-004 : crossing A's withdrawal acknowledged: DONE
// @goal 8 REQ-LC-003 REQ-LC-014 : crossing A CLOSED for the train, confirmation lost: the train stays REQUESTED
// @goal 10 REQ-LC-006 REQ-LC-014 : barrier of A stuck up: FAILED at the barrier timeout
// @goal 11 REQ-LC-006 : boundary: barriers of A detected down in the last cycle before the timeout
// @goal 12 REQ-LC-006 REQ-LC-014 : down detection of A lost while CLOSED: FAILED
// @goal 13 REQ-LC-007 : A: OPENING to OPEN (barriers up)
// @goal 14 REQ-LC-007 REQ-LC-014 : barriers of A not up by the timeout: FAILED
// @goal 15 REQ-LC-007 : end of warning of A (CLOSED to OPENING)
// @goal 16 REQ-LC-006 : boundary: barriers of A detected down in the first cycle after the command
// @goal 17 REQ-LC-004 : boundary: the rear exactly at A's far edge: PASSED, withdrawal
// @goal 18 REQ-LC-004 : boundary: front beyond A's far edge, rear not: still CLEARED, no withdrawal
// @goal 19 REQ-LC-003 : boundary: the train arrives at A exactly when its warning has lasted W
// @goal 20 REQ-LC-002 REQ-LC-001 : boundary: crossing B requested at exactly ETA = W + LEAD
// @goal 21 REQ-LC-002 REQ-LC-005 : boundary: crossing B not requested at ETA one tick above W + LEAD (no ETA of the geometry lies strictly between)
// @goal 22 REQ-LC-005 : boundary: crossing B requested in the dwell at exactly remaining dwell + ETA from rest = W + LEAD
// @goal 23 REQ-LC-003 : boundary: crossing B cleared with the warning time exactly sufficient
// @goal 24 REQ-LC-003 : crossing B not cleared: CLOSED for the train but warned too short for its ETA [config LONG_WARNING]
// @goal 25 REQ-LC-003 REQ-LC-014 : boundary: crossing B not cleared on a CLOSED report one tick older than the confirmation age
// @goal 26 REQ-LC-003 REQ-LC-014 : crossing B's clearance revoked by a FAILED report
// @goal 27 REQ-LC-004 : crossing B's withdrawal acknowledged: DONE
// @goal 28 REQ-LC-003 REQ-LC-014 : crossing B CLOSED for the train, confirmation lost: the train stays REQUESTED
// @goal 30 REQ-LC-006 REQ-LC-014 : barrier of B stuck up: FAILED at the barrier timeout
// @goal 31 REQ-LC-006 : boundary: barriers of B detected down in the last cycle before the timeout
// @goal 32 REQ-LC-006 REQ-LC-014 : down detection of B lost while CLOSED: FAILED
// @goal 33 REQ-LC-007 : B: OPENING to OPEN (barriers up)
// @goal 34 REQ-LC-007 REQ-LC-014 : barriers of B not up by the timeout: FAILED
// @goal 35 REQ-LC-007 : end of warning of B (CLOSED to OPENING)
// @goal 36 REQ-LC-006 : boundary: barriers of B detected down in the first cycle after the command
// @goal 37 REQ-LC-004 : boundary: the rear exactly at B's far edge: PASSED, withdrawal
// @goal 38 REQ-LC-004 : boundary: front beyond B's far edge, rear not: still CLEARED, no withdrawal
// @goal 39 REQ-LC-003 : boundary: the train arrives at B exactly when its warning has lasted W
// ONBOARD, both crossings and the train
// @goal 40 REQ-LC-005 : standing in the dwell, ETA from rest within W + LEAD but the remaining dwell counted: no request yet
// @goal 41 REQ-LC-003 : boundary: the train stands exactly at the protection limit of a crossing not cleared
// @goal 42 REQ-LC-003 REQ-LC-014 : the protection limit makes the train brake (no confirmation in time)
// @goal 43 REQ-LC-006 : two crossings warning at once
// @goal 44 REQ-LC-003 : both crossings cleared at once
// @goal 45 REQ-LC-002 REQ-LC-014 : a request lost: A still OPEN after the train requested it
// @goal 46 REQ-LC-002 : a delayed request starts A's warning a tick later
// @goal 47 REQ-LC-004 REQ-LC-014 : a withdrawal lost: A stays CLOSED, the withdrawal is repeated
// @goal 48 REQ-LC-004 REQ-LC-007 : a delayed withdrawal ends A's warning a tick later
// @goal 49 REQ-LC-005 : departure from the station after the dwell with A cleared
// @goal 50 REQ-LC-005 REQ-LC-003 : departure from the station with A not yet cleared (the protection applies)
// @goal 51 REQ-LC-004 REQ-LC-007 : both crossings passed and withdrawn (DONE)
// @goal 56 REQ-LC-003 REQ-LC-014 : the train on A after its barriers failed under the cleared train (lights warning)
// @goal 57 REQ-LC-005 : the train stops at the station and dwells
// @goal 58 REQ-LC-004 : a repeated withdrawal acknowledged again after A opened (the first acknowledgement lost)
// TWO_TRAINS: a second train requesting crossing A
// @goal 52 REQ-LC-007 : the second train holds A's warning after the train's withdrawal [config TWO_TRAINS]
// @goal 53 REQ-LC-006 REQ-LC-007 : a request while OPENING starts a new warning with a new warning start [config TWO_TRAINS]
// @goal 54 REQ-LC-007 : the second train's withdrawal ends A's warning [config TWO_TRAINS]
// @goal 55 REQ-LC-006 : A's warning started by the second train before the train requested it [config TWO_TRAINS]
// @goal 59 REQ-LC-003 : a CLOSED report of A that does not list the train (closed for the second train) clears nothing [config TWO_TRAINS]

#ifdef TRAPS
#include "lc_goals.pml"
#endif
