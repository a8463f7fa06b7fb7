/*
 * railproof — level-crossing protection: the on-board-requested warning with a protection
 * pattern (D5 §5.3) and the GNSS-time pre-armed crossings of low-cost lines (D4 §4.8.2);
 * spec/design/lc.md §6. C++: lc::onboard::CrossingProtection::Cycle
 * (cpp/runtime/lc/src/onboard/crossing_protection.cpp), lc::wayside::CrossingController::Cycle
 * (cpp/runtime/lc/src/wayside/crossing_controller.cpp), lc::wayside::CentreScheduler::Cycle
 * (cpp/runtime/lc/src/wayside/centre_scheduler.cpp).
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
 * GNSS configuration (design §5). The centre (StartDeparture at time 0 with t_dep = GDWELL,
 * start times re-sent until acknowledged, the departure signal, recomputation from position
 * reports, the warning stop after the passage report), both controllers (stored start time,
 * autonomous start, earlier / later updates, warning stop, clock) and the train, which leaves
 * the station on the departure signal and has no protection pattern (low-cost lines). A tick
 * runs the centre's cycle, then the controllers'. Every centre <-> controller telegram and
 * every position report arrives in its tick, one tick late or is lost; on these links only
 * the newest telegram due in a cycle is delivered (an older one due with it is discarded, as
 * if lost). Position reports carry the time they were taken, the front rounded up and the
 * rear rounded down to whole cells (an envelope) and as speed bound 0 while standing at the
 * station and MODEL_VMAX once departed (the bound over the report's lifetime): every start
 * time is then a whole number of half-ticks, kept exactly. The GNSS configurations keep
 * absolute time (start times are compared with each other) and bound the environment: the
 * search covers every run of up to GNSS_HORIZON ticks with up to GNSS_FAULTS telegram losses
 * or delays, clock faults and GNSS outages (an outage counts once, however long); every run in
 * which the train leaves and passes both crossings fits in the horizon.
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
 * within the confirmation age (REQ-LC-015); GNSS (losses, delays, barrier faults); GNSS_CLOCK
 * (GNSS outages, holdover and clock faults, losses, working barriers); GNSS_FAIR (GNSS with
 * FAIR's radio and barriers); WALK stops after MODEL_CYCLES ticks (random walks); TRAPS adds
 * the goal flags.
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
#include "lc_params.pml"

// @pan_flags -DCOLLAPSE

/* ---- configurations --------------------------------------------------------------------- */
#ifdef GNSS_FAIR
#define GNSS
#define FAIR_RADIO
#define NO_FAIL
#endif
#ifdef GNSS_CLOCK
#define GNSS
#define CLOCK_EVENTS            /* GNSS outages and clock faults */
#define NO_FAIL
#define GNSS_NO_LINK_DELAY
#endif
#ifdef GNSS
#ifdef GNSS_NO_LINK_DELAY
#define GL_DELAY false          /* centre <-> controller telegrams: lost, not late */
#else
#define GL_DELAY (DMAX >= 1)
#endif
#endif
#ifdef FAIR
#define FAIR_RADIO
#define NO_FAIL
#endif
#ifdef HEALTHY
#define NO_LOSS
#define NO_FAIL
#define PROMPT_BARRIERS
#endif
#ifdef TWO_TRAINS
#define OTHER                   /* the second train at crossing A */
#define NO_FAIL
#endif
#ifdef LONG_WARNING
#define WARN_EXTRA 1            /* crossings with a design warning time one tick longer */
#else
#define WARN_EXTRA 0
#endif

/* ---- bounds ------------------------------------------------------------------------------ */
/* model-local bounds (not yet in spec/parameters/lc.yaml model_bounds) */
#ifndef MODEL_LEAD_TICKS
#define MODEL_LEAD_TICKS 3      /* request lead: the smallest that satisfies REQ_LC_015 */
#endif
#ifndef MODEL_CONF_AGE_TICKS
#define MODEL_CONF_AGE_TICKS 0  /* confirmation age: a report of this cycle (issued at now) */
#endif
#ifndef MODEL_PROT_OFFSET
#define MODEL_PROT_OFFSET 1     /* protection limit: one cell before the near edge */
#endif
#ifndef MODEL_DWELL_TICKS
#define MODEL_DWELL_TICKS (MODEL_LEAD_TICKS + 1)  /* longer than the lead: the dwell counts */
#endif
#ifndef MODEL_GNSS_DWELL_TICKS
#define MODEL_GNSS_DWELL_TICKS 2  /* t_dep of the GNSS departure (StartDeparture at 0) */
#endif
#ifndef MODEL_HOLDOVER_TICKS
#define MODEL_HOLDOVER_TICKS 1  /* a GNSS outage longer than this makes the clock faulty */
#endif
#ifndef MODEL_RESPONSE_TICKS
#define MODEL_RESPONSE_TICKS 4  /* bounded response: the smallest that satisfies REQ_LC_007_ends */
#endif
#ifndef MODEL_GNSS_FAULTS
#define MODEL_GNSS_FAULTS 2     /* GNSS: telegram losses and delays, clock faults and outages
                                   (an outage counts once, however long) per run */
#endif
#ifndef MODEL_GNSS_HORIZON
#define MODEL_GNSS_HORIZON 14   /* GNSS: ticks covered by the (absolute-time) search */
#endif

#define W (MODEL_WARN_TICKS + WARN_EXTRA)
#define LOWER MODEL_LOWER_TICKS
#define TO (W - LOWER)
#define LEAD MODEL_LEAD_TICKS
#define CMA MODEL_CONF_AGE_TICKS
#define PO MODEL_PROT_OFFSET
#define DWELL MODEL_DWELL_TICKS
#define GDWELL MODEL_GNSS_DWELL_TICKS
#define HOLD MODEL_HOLDOVER_TICKS
#define RESP MODEL_RESPONSE_TICKS
#define HZ MODEL_GNSS_HORIZON
#define NFB MODEL_GNSS_FAULTS
#define VMAX MODEL_VMAX
#define DMAX MODEL_MAX_DELAY
#define WCAP W                  /* warning age cap: W and LOWER + TO are the largest read */
#define L2 (2 * MODEL_TRAIN_LEN)
#define STA (2 * MODEL_STATION)
#define XEND (2 * MODEL_TRACK)
#define NEAR(i) ((i) == 0 -> 2 * MODEL_LC_A : 2 * MODEL_LC_B)
#define FAR(i) (NEAR(i) + 2)
#define LIM(i) (NEAR(i) - 2 * PO)
#define NOLIM 255

#if MODEL_LOWER_TICKS < 1 || MODEL_WARN_TICKS <= MODEL_LOWER_TICKS
#error "need 1 <= LOWER < W (the timeout W - LOWER is at least one tick)"
#endif
#if MODEL_CONF_AGE_TICKS != 0
#error "the freshness property REQ_LC_003_fresh reads the controller of this cycle: CMA = 0"
#endif
#if MODEL_MAX_DELAY > 1
#error "the channels hold one delayed telegram per link (MODEL_MAX_DELAY <= 1)"
#endif
#if !(MODEL_STATION < MODEL_LC_A - MODEL_PROT_OFFSET && MODEL_LC_A < MODEL_LC_B && MODEL_LC_B < MODEL_TRACK)
#error "geometry: station before the first protection limit, crossings in order inside the track"
#endif
#ifdef GNSS
#if MODEL_VMAX != 2
#error "GNSS: start times are kept in half-ticks, exact for a speed bound of 2 cells/tick"
#endif
#endif

/* ---- enumerations (C++ ToString order) ------------------------------------------------ */
/* controller states (lc::wayside::ControllerState) */
#define C_OPEN 0
#define C_WARN 1
#define C_CLOSING 2
#define C_CLOSED 3
#define C_OPENING 4
#define C_FAILED 5
/* on-board states (lc::onboard::CrossingState) */
#define O_APP 0
#define O_REQ 1
#define O_CLR 2
#define O_PAS 3
#define O_DONE 4
/* report status (messages::CrossingStatus); a delivered report is kept as status + 1 */
#define R_OPEN 0
#define R_WARN 1
#define R_CLOSED 2
#define R_FAILED 3
#define STATUS(c) ((c) == C_CLOSED -> R_CLOSED : ((c) == C_FAILED -> R_FAILED : \
                   (((c) == C_WARN || (c) == C_CLOSING) -> R_WARN : R_OPEN)))
#define WARNING(c) ((c) != C_OPEN && (c) != C_OPENING)
/* train -> ground telegrams */
#define M_NONE 0
#define M_REQ 1
#define M_WD 2
/* station phase */
#define P_BEFORE 0
#define P_DWELL 1
#define P_GONE 2
/* clock input (lc::wayside::ClockInput) and clock state (wayside::ClockState) */
#define K_GNSS 0
#define K_NOGNSS 1
#define K_FAULT 2
#define KS_SYNC 0
#define KS_HOLD 1
#define KS_FAULTY 2

#define MIN(a, b) ((a) < (b) -> (a) : (b))
#define SAT(x, cap) if :: (x) < (cap) -> x++ :: else -> skip fi
#define ON(cond, k) if :: (cond) -> GOAL(k) :: else -> skip fi
#define CHOOSE_BIT(b) if :: b = 0 :: b = 1 fi
/* Every nondeterministic choice is one transition that sets a transient (the breadth-first
 * search stores the states inside a tick), consumed and cleared by the d_step after it. */
#define F_NOW 0
#define F_LATE 1
#define F_LOST 2
#define PICK_FATE(can_delay, can_lose) \
  if \
  :: fate = F_NOW \
  :: d_step { (can_delay) -> fate = F_LATE } \
  :: d_step { (can_lose) -> fate = F_LOST } \
  fi
#define PICK_BARRIER(i) \
  if \
  :: fb = 1 \
  :: d_step { BAR_CAN_MISS(i) -> fb = 0 } \
  fi
#define PICK_SPEED \
  if \
  :: nv = lo \
  :: d_step { hi >= lo + 1 -> nv = lo + 1 } \
  :: d_step { hi >= lo + 2 -> nv = lo + 2 } \
  fi

/* ---- state -------------------------------------------------------------------------------- */
/* train: front (half-cells), speed (cells/tick), station phase, remaining minimum dwell */
byte x, v, ph, dw;
/* controllers */
byte cs[2], wa[2], tm[2];      /* state, warning age now - ws (capped WCAP), OPENING timer */
bit g_exc[2];                  /* ghost: the barriers lost their down detection while the train
                                  was cleared for the crossing (a detected failure under a
                                  cleared train: the lights keep warning, ASM-030) */
#if defined(FAIR_RADIO) || defined(HEALTHY)
byte g_w[2];                   /* ghost: ticks the crossing has warned since the rear passed */
#endif
#ifndef GNSS
byte ob[2];                    /* on-board state per crossing */
bit rq[2];                     /* the train is among the controller's requesters */
bit ackd[2];                   /* the controller acknowledged a withdrawal in this tick */
byte dold[2];                  /* report of the tick before last, delayed: status + 1, 0 none */
bit doreq[2], doack[2];        /* its requester list holds the train; its acknowledgement */
#ifdef MUTANT_STALE_CONFIRMATION
byte dowa[2];                  /* mutant only: its warning age at issue */
#endif
byte uold[2];                  /* train -> ground telegram of the last tick, delayed */
bit g_due[2];                  /* ghost: the train's ETA was within W + LEAD in some cycle */
#ifdef OTHER
byte ost;                      /* second train at A: 0 not yet, 1 requesting, 2 withdrawn */
bit orq;                       /* the second train is among A's requesters */
#endif
#else
byte now;                      /* GNSS: absolute time (ticks) */
byte nf;                       /* GNSS: faults (losses, delays, clock events) so far, <= NFB */
/* centre (half-tick times + OFS) */
byte ist[2], cst[2];           /* initial start time, start time last computed and sent */
bit cpend[2], cack[2], cpass[2], spend[2], sack[2], ccf[2], clr;
/* controllers: pending departure (present, start, active), clock state, outage ticks */
bit pres[2], act[2], stp[2];   /* ... and the departure's warning stop was received */
byte pst[2], ck[2], ho[2];
bit g_st[2];                   /* ghost: the controller stored a start time <= the initial one */
/* links (newest wins): centre -> controller (start + 1, 0 none; stop), controller -> centre
 * (ack: start in force + 1, 0 none; accepted; stop ack; clock fault), position report
 * (front + 1, 0 none; standing; time) */
bit dpo[2]; byte dso[2]; bit dsto[2];
bit upo[2]; byte uao[2]; bit uaco[2], usto[2], ucfo[2];
bit ppo; byte pxo; bit psto;
/* this tick's controller -> centre telegram (issued by the controllers' cycle) */
byte uan[2]; bit uacn[2], ustn[2];
#endif
#ifdef FAIR_RADIO
bit ul_l[2], dl_l[2], pr_l;    /* the last telegram of the link was lost */
#endif
#ifdef WALK
byte ncycles;
#endif

/* ---- transients (cleared when consumed, at the latest at the end of the tick) --------------- */
byte eta[2];                   /* ETA of the cycle (half-ticks), APPROACHING..CLEARED */
byte r2[2], r1[2];             /* reports delivered to the on-board: age 1, age 0 (status + 1) */
bit r2r[2], r1r[2], r2a[2], r1a[2];  /* their requester bit and acknowledgement */
byte u1[2], u0[2];             /* train -> ground telegrams delivered: last tick's, this tick's */
bit rin[2];                    /* a request of the train arrived at the controller */
bit down[2], up[2];            /* barrier detection */
byte fate;                     /* the radio's choice for a telegram (F_NOW, F_LATE, F_LOST) */
bit fb;                        /* the barrier's choice: at its commanded position (1) or not */
byte oev;                      /* second train: 0 nothing, 1 request, 2 withdrawal delivered */
bit wsn[2];                    /* a new warning started in this cycle (ws = now) */
byte lim, lo, hi, hif, nv;     /* protection limit; motion: lowest, highest, highest without
                                  protection, chosen speed */
byte was_x, was_v, was_ph, was_dw, was_cs[2], was_wa[2], was_ob[2], mid_ob[2];
byte e_r, e_t, e_s, e_n, e_d, c, wn;
short sd;
#ifdef GNSS
byte ds[2]; bit dst[2];        /* centre -> controller delivered: start + 1, stop */
byte ua[2]; bit uac[2], ust[2], ucf[2], urx[2];  /* controller -> centre delivered */
byte px; bit pstd; byte pt;    /* position report delivered: front + 1 (0 none), standing, time */
byte kin[2];                   /* clock input */
byte acc_n, was_pst;
bit was_act;
bit was_pres[2], was_clr, was_cpass, ds_in[2], ua_late;
byte was_ck[2];
#endif

/* ---- ghost: latched property violations ---------------------------------------------------- */
bit v_occ, v_fresh, v_end, v_live, v_req, v_ctrl, v_brake, v_dep, v_start, v_clock, v_later;

#ifdef TRAPS
#define NGOALS 104
bit g[NGOALS];
byte h_i;
/* goal flags mark the goals reached in the last tick only (cleared at the start of each
 * tick), so that they do not multiply the states of the breadth-first trap searches */
#define GOAL(k) g[k] = 1
#define CLEAR_GOALS d_step { for (h_i : 0 .. NGOALS - 1) { g[h_i] = 0 }; h_i = 0 }
#else
#define GOAL(k) skip
#define CLEAR_GOALS skip
#endif

/* ---- earliest arrival (design §2) ------------------------------------------------------------
 * eta2 (half-ticks, see the header) of the front `d` half-cells before the target at speed
 * `vv`, accelerating at 1 cell/tick² up to VMAX, plus `dwl` whole ticks of remaining dwell (0
 * once reached):
 * the first whole tick t at which the run reaches d, minus one half-tick if it reaches it
 * before t (the run is exact at whole ticks: speeds are whole numbers there). Arguments must
 * be variables (no conditional expressions). */
inline eta_of(d, vv, dwl, res) {
  if
  :: d <= 0 -> res = 0
  :: else ->
     e_r = 0; e_t = 0; e_s = vv;
     do
     :: e_r < d ->
        e_n = (e_s < VMAX -> e_s + 1 : VMAX);
        e_r = e_r + e_s + e_n; e_s = e_n; e_t++
     :: else -> break
     od;
     res = 2 * e_t - (e_r == d -> 0 : 1) + 2 * dwl
  fi;
  e_r = 0; e_t = 0; e_s = 0; e_n = 0
}

#ifdef FAIR_RADIO
#define CAN_LOSE(bitv) (!(bitv))
#define LOST(bitv, b) bitv = b
#else
#ifdef NO_LOSS
#define CAN_LOSE(bitv) false
#else
#define CAN_LOSE(bitv) true
#endif
#define LOST(bitv, b) skip
#endif

/* ---- configuration-specific predicates of the shared parts -----------------------------------
 * TRIGGER(i): the controller's warning trigger (a requester / the pending departure active or
 * the clock faulty); ENDS(i): the end of warning of a CLOSED crossing; SHOULD_WARN(i): a
 * trigger arrived or holds (REQ-LC-006); EXCUSED(i): a FAILED crossing the train may occupy;
 * NEEDED(i): the train needs the warning until its rear passed; CLEARED_NOW(i): the train is
 * cleared for the crossing; MAY_DEPART: the departure is authorised */
#ifndef GNSS
#define MAY_DEPART true
#define DWELL_HOLDS (dw > 0)     /* the departure is not authorised before t_dep */
#define EXCUSED(i) g_exc[i]
#define NEEDED(i) (ob[i] >= O_CLR)   /* cleared (or beyond): it relies on the warning */
#define CLEARED_NOW(i) (ob[i] == O_CLR)
#ifdef OTHER
#define OREQ(i) ((i) == 0 && orq)
#else
#define OREQ(i) 0
#endif
#define TRIGGER(i) (rq[i] || OREQ(i))
#define SHOULD_WARN(i) (rin[i])
#define ENDS(i) (!rq[i] && !OREQ(i))
#else
#define OFS (2 * W)            /* times: half-ticks + OFS, so that a start time is never negative */
#define NOW2 (2 * now + OFS)
#define MAY_DEPART clr
#define DWELL_HOLDS false        /* the train leaves on the departure signal */
#define EXCUSED(i) true        /* no train-side protection: a FAILED crossing keeps warning */
#define NEEDED(i) true
#define CLEARED_NOW(i) 0
#ifdef MUTANT_CLOCK_FAULT_IGNORED
#define FAULTY(i) false
#else
#define FAULTY(i) (ck[i] == KS_FAULTY)
#endif
#define TRIGGER(i) (act[i] || FAULTY(i))
#define SHOULD_WARN(i) TRIGGER(i)
#define ENDS(i) (!act[i] && !FAULTY(i))
#endif

/* ---- barrier detection: free where the controller reads it, within its timeout where the
 * crossing works (NO_FAIL), at once where PROMPT_BARRIERS ----------------------------------- */
#ifdef PROMPT_BARRIERS
#define MISS_CLOSING(i) false
#define MISS_OPENING(i) false
#elif defined(NO_FAIL)
#define MISS_CLOSING(i) (wa[i] + 1 < LOWER + TO)
#define MISS_OPENING(i) (tm[i] + 1 < TO)
#else
#define MISS_CLOSING(i) true
#define MISS_OPENING(i) true
#endif
#ifdef NO_FAIL
#define MISS_CLOSED(i) false
#else
#define MISS_CLOSED(i) true
#endif
#define BAR_CAN_MISS(i) ((cs[i] == C_CLOSING && MISS_CLOSING(i)) || (cs[i] == C_CLOSED && MISS_CLOSED(i)) || \
                         (cs[i] == C_OPENING && MISS_OPENING(i)))
/* the detection from the choice fb: CLOSING/CLOSED: down = fb; OPENING: up = fb */
inline barrier(i) {
  if
  :: cs[i] == C_CLOSING -> down[i] = fb; up[i] = !fb
  :: cs[i] == C_CLOSED -> down[i] = fb; up[i] = 0
  :: cs[i] == C_OPENING -> up[i] = fb; down[i] = !fb
  :: cs[i] == C_FAILED -> down[i] = 0; up[i] = 0
  :: else -> down[i] = 0; up[i] = 1
  fi;
  fb = 0
}

/* ---- controller: one transition (design §4 step 4, CrossingController::Cycle) ---------------
 * TRIGGER(i): a requester (ONBOARD) / the pending departure active or the clock faulty (GNSS);
 * ENDS(i): the end of warning of a CLOSED crossing */
#ifdef MUTANT_LOWER_LATE
#define LOWER_AT (LOWER + 1)
#else
#define LOWER_AT LOWER
#endif
inline ctrl_timers(i) {
  was_cs[i] = cs[i]; was_wa[i] = wa[i];
  if :: cs[i] != C_OPEN && cs[i] != C_OPENING -> SAT(wa[i], WCAP) :: else -> skip fi;
  if :: cs[i] == C_OPENING -> SAT(tm[i], TO) :: else -> skip fi
}

inline ctrl_transition(i) {
  if
  :: cs[i] == C_OPEN || cs[i] == C_OPENING ->
     if
     :: TRIGGER(i) -> cs[i] = C_WARN; wa[i] = 0; tm[i] = 0; wsn[i] = 1
     :: else ->
        if
        :: cs[i] == C_OPENING && up[i] -> cs[i] = C_OPEN; tm[i] = 0
        :: cs[i] == C_OPENING && !up[i] && tm[i] >= TO -> cs[i] = C_FAILED; tm[i] = 0
        :: else -> skip
        fi
     fi
  :: cs[i] == C_WARN -> if :: wa[i] >= LOWER_AT -> cs[i] = C_CLOSING :: else -> skip fi
  :: cs[i] == C_CLOSING ->
     if
#ifndef MUTANT_CLOSED_WITHOUT_DOWN
     :: down[i] -> cs[i] = C_CLOSED
     :: !down[i] && wa[i] >= LOWER + TO -> cs[i] = C_FAILED
#else
     :: down[i] || wa[i] >= LOWER + TO -> cs[i] = C_CLOSED
#endif
     :: else -> skip
     fi
  :: cs[i] == C_CLOSED ->
     if
     :: !down[i] -> cs[i] = C_FAILED; g_exc[i] = CLEARED_NOW(i)
     :: down[i] && ENDS(i) -> cs[i] = C_OPENING; tm[i] = 0; wa[i] = 0
     :: else -> skip
     fi
  :: cs[i] == C_FAILED -> skip
  fi;
  /* REQ-LC-006: the controller's sequence */
  if
  :: cs[i] == C_CLOSED && !down[i] -> v_ctrl = 1                 /* CLOSED only while down */
  :: was_cs[i] == C_FAILED && cs[i] != C_FAILED -> v_ctrl = 1    /* FAILED is kept */
  :: cs[i] == C_WARN && !wsn[i] && was_wa[i] + 1 >= LOWER -> v_ctrl = 1   /* down at LOWER */
  :: cs[i] == C_CLOSING && !down[i] && was_wa[i] + 1 >= LOWER + TO -> v_ctrl = 1
  :: (was_cs[i] == C_OPEN || was_cs[i] == C_OPENING) && SHOULD_WARN(i) && !(cs[i] == C_WARN && wsn[i]) ->
     v_ctrl = 1
  :: else -> skip
  fi
}

/* ---- train motion ---------------------------------------------------------------------------
 * lo = the hardest braking, hif = the highest speed the station, the dwell (or the departure
 * signal) and the end of the track allow, hi = the highest the protection limit allows too */
#define STOPS_BY(vv, bound) (x + v + (vv) + (vv) * (vv) <= (bound))
inline motion_bounds() {
  was_x = x; was_v = v; was_ph = ph; was_dw = dw;
  lo = (v > 0 -> v - 1 : 0);
  hif = (v < VMAX -> v + 1 : VMAX);
  if :: ph == P_DWELL && (DWELL_HOLDS || !MAY_DEPART) -> hif = 0 :: else -> skip fi;
  do
  :: hif > lo && !(STOPS_BY(hif, XEND) && (ph != P_BEFORE || STOPS_BY(hif, STA))) -> hif--
  :: else -> break
  od;
  hi = hif;
  do
  :: hi > lo && lim != NOLIM && !STOPS_BY(hi, lim) -> hi--
  :: else -> break
  od
}

inline move() {
  x = x + v + nv; v = nv;
  if
  :: ph == P_BEFORE && x == STA && v == 0 -> ph = P_DWELL; dw = DWELL
  :: ph == P_DWELL && v > 0 -> ph = P_GONE; dw = 0
  :: ph == P_DWELL && v == 0 && dw > 0 -> dw--
  :: else -> skip
  fi
}

/* the train occupies crossing i at the start of the tick, or enters it strictly inside it (an
 * arrival exactly at the tick's end is checked in the next tick); the controller's state in
 * the tick is the one after its cycle */
#define OCC(i) ((was_x >= NEAR(i) && was_x < FAR(i) + L2) || (was_x < NEAR(i) && x > NEAR(i)))
#define REAR_PASSED(i) (was_x >= FAR(i) + L2)

inline check_common(i) {
  /* REQ-LC-003/-006/-011/-014: only a crossing that has warned W at the arrival (ws + W <=
   * arrival) and is CLOSED, or FAILED as EXCUSED allows */
  if
  :: OCC(i) && !(wa[i] >= W && (cs[i] == C_CLOSED || (cs[i] == C_FAILED && EXCUSED(i)))) -> v_occ = 1
  :: else -> skip
  fi;
  /* REQ-LC-007/-012: the warning ends (CLOSED to OPENING) only once the rear has passed
   * (ONBOARD: checked in the controllers' cycle, ctrl_step) */
#ifdef GNSS
  if
  :: was_cs[i] == C_CLOSED && cs[i] == C_OPENING && NEEDED(i) && !REAR_PASSED(i) -> v_end = 1
  :: else -> skip
  fi;
#endif
#if defined(FAIR_RADIO) || defined(HEALTHY)
  /* bounded response: the warning ends (OPEN) within RESP ticks after the rear passed */
  if
  :: REAR_PASSED(i) && cs[i] != C_OPEN -> SAT(g_w[i], RESP + 1)
  :: else -> g_w[i] = 0
  fi;
  if :: g_w[i] > RESP -> v_live = 1 :: else -> skip fi
#endif
}

#ifndef GNSS
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
#endif /* !GNSS */

#ifdef GNSS
/* ======================================================================================= *
 * GNSS-time pre-armed crossings (design §5)                                                *
 * ======================================================================================= */
#ifdef MUTANT_LATER_UPDATE_WHILE_WARNING
#define LATER_OK(i) true
#else
#define LATER_OK(i) (cs[i] == C_OPEN && !act[i])
#endif
#if defined(MUTANT_DEPART_WITHOUT_ALL_ACKS)
#define ALL_ACKED (cack[0] || cack[1])
#else
#define ALL_ACKED (cack[0] && cack[1])
#endif
#define START_FROM GDWELL
#ifdef MUTANT_DEPART_BEFORE_TDEP
#define TDEP_REACHED true
#else
#define TDEP_REACHED (now >= GDWELL)
#endif
/* position report of the train at time t with front x (half-cells): the envelope front
 * rounded up, the rear rounded down to whole cells; speed bound 0 (standing at the station
 * before its departure) or VMAX */
#define REP_FRONT(xx) (((xx) + 1) / 2)
#define REP_REAR(xx) ((xx) / 2 - MODEL_TRAIN_LEN)

/* the centre's cycle (CentreScheduler::Cycle) on the delivered telegrams */
inline centre_crossing(i, lc) {
  /* 1. the clock fault of the crossing's last report; 2. acknowledgements */
  if
  :: urx[i] ->
     ccf[i] = ucf[i];
     if
     :: ua[i] != 0 && uac[i] ->          /* counted only when stored */
        if :: ua[i] - 1 <= ist[i] -> cack[i] = 1 :: else -> skip fi;
        if :: ua[i] - 1 <= cst[i] -> cpend[i] = 0 :: else -> skip fi
     :: else -> skip
     fi;
     if :: ust[i] && spend[i] -> sack[i] = 1; spend[i] = 0 :: else -> skip fi
  :: else -> skip
  fi;
  /* 3. the position report: passage (REQ-LC-012) or the recomputed start time (REQ-LC-010) */
  if
  :: px != 0 && !cpass[i] ->
     if
#ifdef MUTANT_STOP_AT_FRONT
     :: REP_FRONT(px - 1) >= lc + 1 -> cpass[i] = 1; spend[i] = 1; cpend[i] = 0
#else
     :: REP_REAR(px - 1) >= lc + 1 -> cpass[i] = 1; spend[i] = 1; cpend[i] = 0
#endif
     :: else ->
        if
        :: pstd ->   /* standing at the station: from max(t, t_dep), from rest */
           e_d = (pt < GDWELL -> GDWELL : pt); sd = NEAR(i) - STA; c = 0; eta_of(sd, c, c, wn);
           c = 2 * e_d + wn
        :: else ->   /* speed bound VMAX = 2: lc - front cells take as many half-ticks */
#ifdef MUTANT_UPDATE_FROM_REST
           sd = 2 * lc - 2 * REP_FRONT(px - 1); c = 0; eta_of(sd, c, c, wn); c = wn;
#else
           c = (REP_FRONT(px - 1) < lc -> lc - REP_FRONT(px - 1) : 0);
#endif
           c = 2 * pt + c
        fi;
        /* st' = t + ETA - W (+ OFS = 2W): c */
        if :: c != cst[i] -> cst[i] = c; cpend[i] = 1 :: else -> skip fi;
        e_d = 0; wn = 0; c = 0; sd = 0
     fi
  :: else -> skip
  fi
}

inline centre() {
  centre_crossing(0, MODEL_LC_A);
  centre_crossing(1, MODEL_LC_B);
  /* 4. the departure signal */
  clr = ALL_ACKED && !ccf[0] && !ccf[1] && TDEP_REACHED
}

/* The controller's telegram of the last tick (acknowledgements, clock fault: the clock is as
 * it was, no controller cycle ran since) and the delayed one of the tick before: the newest
 * due is delivered, an older one due with it is discarded. */
inline deliver_uold(i) {
  if
  :: upo[i] -> urx[i] = 1; ua[i] = uao[i]; uac[i] = uaco[i]; ust[i] = usto[i]; ucf[i] = ucfo[i];
     ua_late = 1; printf("@IN ua c=%d age=2\n", i)
  :: else -> skip
  fi;
  upo[i] = 0; uao[i] = 0; uaco[i] = 0; usto[i] = 0; ucfo[i] = 0
}
inline uplink_g(i) {
  if
  :: now == 0 -> skip
  :: now > 0 && fate == F_NOW ->
     upo[i] = 0; uao[i] = 0; uaco[i] = 0; usto[i] = 0; ucfo[i] = 0;
     urx[i] = 1; ua[i] = uan[i]; uac[i] = uacn[i]; ust[i] = ustn[i]; ucf[i] = FAULTY(i);
     LOST(ul_l[i], 0); printf("@IN ua c=%d age=1\n", i)
  :: now > 0 && fate == F_LATE ->
     deliver_uold(i);
     upo[i] = 1; uao[i] = uan[i]; uaco[i] = uacn[i]; usto[i] = ustn[i]; ucfo[i] = FAULTY(i);
     LOST(ul_l[i], 0)
  :: now > 0 && fate == F_LOST -> deliver_uold(i); LOST(ul_l[i], 1)
  fi;
  if :: now > 0 && fate != F_NOW -> nf++ :: else -> skip fi;
  uan[i] = 0; uacn[i] = 0; ustn[i] = 0; fate = 0
}
#define PICK_UPLINK_G(i) PICK_FATE(now > 0 && GL_DELAY && nf < NFB, now > 0 && CAN_LOSE(ul_l[i]) && nf < NFB)

/* The centre's telegram of this tick to controller i (start time if pending, warning stop if
 * pending) and the delayed one of the last tick: the newest due is delivered. */
inline deliver_dold(i) {
  if
  :: dpo[i] -> ds[i] = dso[i]; dst[i] = dsto[i]; printf("@IN ds c=%d age=1\n", i)
  :: else -> skip
  fi;
  dpo[i] = 0; dso[i] = 0; dsto[i] = 0
}
#define CSTART(i) (cpend[i] -> cst[i] + 1 : 0)
inline downlink_g(i) {
  if
  :: !cpend[i] && !spend[i] -> deliver_dold(i)
  :: (cpend[i] || spend[i]) && fate == F_NOW ->
     dpo[i] = 0; dso[i] = 0; dsto[i] = 0;
     ds[i] = CSTART(i); dst[i] = spend[i]; LOST(dl_l[i], 0); printf("@IN ds c=%d age=0\n", i)
  :: (cpend[i] || spend[i]) && fate == F_LATE ->
     deliver_dold(i); dpo[i] = 1; dso[i] = CSTART(i); dsto[i] = spend[i]; LOST(dl_l[i], 0)
  :: (cpend[i] || spend[i]) && fate == F_LOST -> deliver_dold(i); LOST(dl_l[i], 1)
  fi;
  if :: (cpend[i] || spend[i]) && fate != F_NOW -> nf++ :: else -> skip fi;
  fate = 0
}
#define PICK_DOWNLINK_G(i) PICK_FATE((cpend[i] || spend[i]) && GL_DELAY && nf < NFB, (cpend[i] || spend[i]) && CAN_LOSE(dl_l[i]) && nf < NFB)

/* The train's position report of this tick and the delayed one of the last tick. */
inline deliver_pold() {
  if
  :: ppo -> px = pxo; pstd = psto; pt = now - 1; printf("@IN pos age=1\n")
  :: else -> skip
  fi;
  ppo = 0; pxo = 0; psto = 0
}
inline posrep() {
  if
  :: fate == F_NOW -> ppo = 0; pxo = 0; psto = 0; px = x + 1; pstd = (ph == P_DWELL); pt = now; LOST(pr_l, 0);
     printf("@IN pos age=0\n")
  :: fate == F_LATE -> deliver_pold(); ppo = 1; pxo = x + 1; psto = (ph == P_DWELL); LOST(pr_l, 0)
  :: fate == F_LOST -> deliver_pold(); LOST(pr_l, 1)
  fi;
  if :: fate != F_NOW -> nf++ :: else -> skip fi;
  fate = 0
}
#define PICK_POSREP PICK_FATE(DMAX >= 1 && nf < NFB, CAN_LOSE(pr_l) && nf < NFB)

/* ---- clock input (REQ-LC-013): GNSS, an outage, or a clock fault ---------------------------- */
#ifdef CLOCK_EVENTS
#define PICK_CLOCK(i) \
  if \
  :: kin[i] = K_GNSS \
  :: d_step { ck[i] == KS_SYNC && nf < NFB -> kin[i] = K_NOGNSS; nf++ } \
  :: d_step { ck[i] == KS_HOLD -> kin[i] = K_NOGNSS } \
  :: d_step { ck[i] != KS_FAULTY && nf < NFB -> kin[i] = K_FAULT; nf++ } \
  fi
#else
#define PICK_CLOCK(i) skip
#endif

/* the controller's cycle, GNSS part (CrossingController::Cycle steps 1, 3, 4) */
inline ctrl_gnss(i, k) {
  printf("@IN clk c=%d k=%d\n", i, kin[i]);
  printf("@IN bar c=%d down=%d up=%d\n", i, down[i], up[i]);
  ctrl_timers(i);
  /* 1. clock */
  if
  :: kin[i] == K_FAULT -> ck[i] = KS_FAULTY; ho[i] = 0
  :: kin[i] == K_NOGNSS && ck[i] == KS_SYNC -> ck[i] = KS_HOLD; ho[i] = 0
  :: kin[i] == K_NOGNSS && ck[i] == KS_HOLD ->
     SAT(ho[i], HOLD + 1);
     if :: ho[i] > HOLD -> ck[i] = KS_FAULTY; ho[i] = 0 :: else -> skip fi
  :: kin[i] == K_GNSS && ck[i] == KS_HOLD -> ck[i] = KS_SYNC; ho[i] = 0
  :: else -> skip
  fi;
  /* 3. the start time (earlier: always; later: only while OPEN and not active), the stop */
  if
  :: ds[i] != 0 ->
     /* the ack: stored (acc_n) with the start time in force, or not stored with the message's */
     acc_n = 1;
     if
     :: stp[i] -> acc_n = 0                /* a late repetition after the warning stop */
     :: !stp[i] && !pres[i] -> pres[i] = 1; pst[i] = ds[i] - 1
     :: !stp[i] && pres[i] && ds[i] - 1 <= pst[i] -> pst[i] = ds[i] - 1
     :: !stp[i] && pres[i] && ds[i] - 1 > pst[i] && LATER_OK(i) -> pst[i] = ds[i] - 1
     :: else -> skip                       /* a later time refused: the earlier stays */
     fi;
     uan[i] = (acc_n -> pst[i] + 1 : ds[i]); uacn[i] = acc_n;
     /* REQ-LC-010: once warning, the start time in force never moves later */
     if :: acc_n && was_pres[i] && pst[i] > was_pst && (was_act || WARNING(cs[i])) -> v_later = 1 :: else -> skip fi;
     if :: pres[i] && pst[i] <= ist[i] -> g_st[i] = 1 :: else -> skip fi;
     ON(acc_n && was_pres[i] && ds[i] - 1 < was_pst, k + 5);
     ON(acc_n && was_pres[i] && ds[i] - 1 > was_pst && pst[i] > was_pst, k + 6);
     ON(acc_n && was_pres[i] && ds[i] - 1 > was_pst && pst[i] == was_pst, k + 7);
     skip
  :: else -> skip
  fi;
  if
  :: dst[i] -> ustn[i] = 1; stp[i] = 1;
     if :: pres[i] -> pres[i] = 0; act[i] = 0; pst[i] = 0 :: else -> skip fi
  :: else -> skip
  fi;
  if :: pres[i] && NOW2 >= pst[i] -> act[i] = 1 :: else -> skip fi;
  /* 4. */
  ctrl_transition(i);
  /* REQ-LC-013: a faulty clock: warning at once */
  if :: ck[i] == KS_FAULTY && !WARNING(cs[i]) -> v_clock = 1 :: else -> skip fi;
  ds[i] = 0; dst[i] = 0; down[i] = 0; up[i] = 0; acc_n = 0
}

/* ---- properties (GNSS) and goals, after the tick ---------------------------------------------- */
inline check() {
  check_common(0);
  check_common(1);
  c = 0;
  do
  :: c < 2 ->
     /* REQ-LC-012: the warning stop only after the rear has passed */
     if :: cpass[c] && !REAR_PASSED(c) -> v_end = 1 :: else -> skip fi;
     /* REQ-LC-008/-010/-011: once the train may move, every crossing it has not passed warns,
      * or holds a start time at least W before the train's earliest arrival from now */
     if
     :: (clr || was_ph == P_GONE) && !REAR_PASSED(c) && !WARNING(cs[c]) ->
        sd = NEAR(c) - was_x; wn = 0; eta_of(sd, was_v, wn, e_d);
        if :: !(pres[c] && pst[c] <= 2 * now + e_d) -> v_start = 1 :: else -> skip fi;
        e_d = 0; sd = 0; wn = 0
     :: else -> skip
     fi;
     c++
  :: else -> break
  od;
  c = 0;
  /* REQ-LC-009/-013: the train departs only once the centre received both controllers'
   * acknowledgements of a start time no later than the initial one (and both stored one), no
   * clock fault is known and t_dep is reached */
  if
  :: was_ph == P_DWELL && ph == P_GONE &&
     !(cack[0] && cack[1] && g_st[0] && g_st[1] && !ccf[0] && !ccf[1] && now >= GDWELL) ->
     v_dep = 1
  :: else -> skip
  fi
}

inline goals_gnss(i, k) {
  ON(was_cs[i] == C_OPEN && wsn[i] && act[i] && pst[i] == NOW2, k + 0);
  ON(was_cs[i] == C_OPEN && wsn[i] && act[i] && !ds_in[i], k + 1);
  ON(was_pres[i] && !pres[i], k + 2);
  ON(was_cs[i] == C_CLOSED && cs[i] == C_OPENING, k + 3);
  ON(was_cs[i] == C_CLOSING && cs[i] == C_FAILED, k + 4);
  ON(kin[i] == K_NOGNSS && ck[i] == KS_HOLD && ho[i] == HOLD, k + 8);
  ON(kin[i] == K_NOGNSS && ck[i] == KS_FAULTY && was_ck[i] == KS_HOLD, k + 9);
  ON(kin[i] == K_FAULT && was_ck[i] != KS_FAULTY, k + 10);
  ON(kin[i] == K_GNSS && was_ck[i] == KS_HOLD, k + 11);
  ON(OCC(i) && was_x == NEAR(i) && wa[i] == W, k + 12)
}

inline goals() {
  goals_gnss(0, 60);
  goals_gnss(1, 75);
  ON(clr && !was_clr, 90);
  ON(now >= GDWELL && !clr && !(cack[0] && cack[1]) && !ccf[0] && !ccf[1], 91);
  ON(now >= GDWELL && !clr && cack[0] && cack[1] && (ccf[0] || ccf[1]), 92);
  ON(cpass[0] && !was_cpass, 93);
  ON(REAR_PASSED(0) && !cpass[0] && WARNING(cs[0]), 94);
  ON(pres[1] && cpend[1] && cst[1] > pst[1], 95);
  ON(ua_late && cack[0] && cack[1], 98);
  ON(WARNING(cs[0]) && WARNING(cs[1]) && cs[0] != C_FAILED && cs[1] != C_FAILED, 99);
  ON(was_ph == P_DWELL && ph == P_GONE && now == GDWELL, 100)
}

inline clear_tick() {
  urx[0] = 0; urx[1] = 0; ua[0] = 0; ua[1] = 0; uac[0] = 0; uac[1] = 0; ust[0] = 0; ust[1] = 0;
  ucf[0] = 0; ucf[1] = 0; px = 0; pstd = 0; pt = 0; kin[0] = 0; kin[1] = 0; wsn[0] = 0; wsn[1] = 0;
  lim = 0; lo = 0; hi = 0; hif = 0; nv = 0;
  was_x = 0; was_v = 0; was_ph = 0; was_dw = 0; was_cs[0] = 0; was_cs[1] = 0; was_wa[0] = 0;
  was_wa[1] = 0; was_pres[0] = 0; was_pres[1] = 0; was_ck[0] = 0; was_ck[1] = 0; was_pst = 0;
  was_clr = 0; was_cpass = 0; was_act = 0; ds_in[0] = 0; ds_in[1] = 0; ua_late = 0; c = 0; wn = 0; sd = 0;
  if :: cs[0] == C_OPEN || cs[0] == C_OPENING -> wa[0] = 0 :: else -> skip fi;
  if :: cs[1] == C_OPEN || cs[1] == C_OPENING -> wa[1] = 0 :: else -> skip fi;
  if :: cs[0] != C_OPENING -> tm[0] = 0 :: else -> skip fi;
  if :: cs[1] != C_OPENING -> tm[1] = 0 :: else -> skip fi;
  now++
}

#define PRINT_GCTRL(i) \
  printf("@OUT gctrl c=%d cs=%d wa=%d new=%d pres=%d pst=%d act=%d ck=%d ack=%d acc=%d sack=%d\n", \
         i, cs[i], wa[i], wsn[i], pres[i], pst[i], act[i], ck[i], uan[i], uacn[i], ustn[i])

init {
  /* the train stands at the station; StartDeparture at time 0 with t_dep = GDWELL */
  d_step {
    x = STA; ph = P_DWELL; dw = GDWELL;
    sd = NEAR(0) - STA; c = 0; eta_of(sd, c, c, e_d); ist[0] = 2 * START_FROM + e_d; cst[0] = ist[0]; cpend[0] = 1;
    sd = NEAR(1) - STA; eta_of(sd, c, c, e_d); ist[1] = 2 * START_FROM + e_d; cst[1] = ist[1]; cpend[1] = 1;
    sd = 0; e_d = 0
  };
end:
  do
  :: atomic {
       now < HZ;
#ifdef WALK
       ncycles < MODEL_CYCLES -> ncycles++;
#endif
       CLEAR_GOALS;
       d_step {
         printf("@IN tick t=%d x=%d v=%d ph=%d dw=%d\n", now, x, v, ph, dw);
         was_clr = clr; was_cpass = cpass[0]
       };
       /* 1. the centre's cycle on the telegrams delivered */
       PICK_POSREP;
       d_step { posrep() };
       PICK_UPLINK_G(0);
       d_step { uplink_g(0) };
       PICK_UPLINK_G(1);
       d_step {
         uplink_g(1);
         centre();
         ON(px != 0 && pt < now && !pstd, 96);
         ON(px != 0 && pstd && pt > GDWELL && cpend[1] && cst[1] > ist[1], 97);
         printf("@OUT centre clr=%d st0=%d p0=%d a0=%d x0=%d sp0=%d sa0=%d cf0=%d st1=%d p1=%d a1=%d x1=%d sp1=%d sa1=%d cf1=%d\n",
                clr, cst[0], cpend[0], cack[0], cpass[0], spend[0], sack[0], ccf[0],
                cst[1], cpend[1], cack[1], cpass[1], spend[1], sack[1], ccf[1]);
         urx[0] = 0; urx[1] = 0; ua[0] = 0; ua[1] = 0; uac[0] = 0; uac[1] = 0; ust[0] = 0; ust[1] = 0;
         ucf[0] = 0; ucf[1] = 0; px = 0; pstd = 0; pt = 0
       };
       /* 2. the controllers' cycles */
       PICK_DOWNLINK_G(0);
       d_step { downlink_g(0) };
       PICK_CLOCK(0);
       PICK_BARRIER(0);
       d_step {
         barrier(0);
         ds_in[0] = (ds[0] != 0 || dst[0]); was_pres[0] = pres[0]; was_pst = pst[0]; was_act = act[0]; was_ck[0] = ck[0];
         ctrl_gnss(0, 60); PRINT_GCTRL(0)
       };
       PICK_DOWNLINK_G(1);
       d_step { downlink_g(1) };
       PICK_CLOCK(1);
       PICK_BARRIER(1);
       d_step {
         barrier(1);
         ds_in[1] = (ds[1] != 0 || dst[1]); was_pres[1] = pres[1]; was_pst = pst[1]; was_act = act[1]; was_ck[1] = ck[1];
         ctrl_gnss(1, 75); PRINT_GCTRL(1);
         lim = NOLIM;
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
#endif /* GNSS */

// @property REQ_LC_003_occupancy REQ-LC-003 REQ-LC-006 REQ-LC-011 REQ-LC-014 : the train never occupies a crossing (front at or beyond the near edge, rear before the far edge, also inside a tick) unless it has warned for at least MODEL_WARN_TICKS at the train's arrival and is CLOSED; ONBOARD: or its barriers lost their down detection while the train was cleared (a detected failure under a cleared train); GNSS: or it FAILED (no train-side protection: the lights keep warning) [config ONBOARD LONG_WARNING TWO_TRAINS FAIR HEALTHY GNSS GNSS_CLOCK]
ltl REQ_LC_003_occupancy { [] !v_occ }
// @property REQ_LC_003_fresh REQ-LC-003 REQ-LC-001 : the on-board unit clears a crossing only on the controller's state of the same cycle (the only report within the confirmation age) being CLOSED with the train among its requesters and a warning start at least MODEL_WARN_TICKS before the train's earliest arrival [config ONBOARD LONG_WARNING TWO_TRAINS FAIR HEALTHY]
ltl REQ_LC_003_fresh { [] !v_fresh }
// @property REQ_LC_007_end REQ-LC-004 REQ-LC-007 REQ-LC-012 : a withdrawal (ONBOARD) or warning stop (GNSS) is sent only after the train's rear has passed the crossing's far edge, and a warning ends (CLOSED to OPENING) only when no requester is left and the train that needed it has passed with its rear [config ONBOARD LONG_WARNING TWO_TRAINS FAIR HEALTHY GNSS GNSS_CLOCK]
ltl REQ_LC_007_end { [] !v_end }
// @property REQ_LC_007_ends REQ-LC-007 REQ-LC-004 REQ-LC-012 : with a working crossing and a fair radio (no link loses two telegrams in a row) the warning of a crossing ends (OPEN) at most MODEL_RESPONSE_TICKS ticks after the train's rear passed it (bounded response: the liveness of design §6 under weak fairness, as a safety property) [config FAIR HEALTHY GNSS_FAIR]
ltl REQ_LC_007_ends { [] !v_live }
// @property REQ_LC_002_request REQ-LC-002 REQ-LC-005 REQ-LC-001 : the request of a crossing is sent in every cycle from the first whose earliest arrival (for a train standing in its dwell: the remaining dwell plus the run from rest) is within the warning time plus the lead, until the rear has passed, and never before [config ONBOARD LONG_WARNING TWO_TRAINS FAIR HEALTHY]
ltl REQ_LC_002_request { [] !v_req }
// @property REQ_LC_006_controller REQ-LC-006 : a controller starts the warning in the cycle a request arrives (GNSS: its stored start time is reached or its clock is faulty), commands the barriers down MODEL_LOWER_TICKS later, is CLOSED only while the barriers are detected down, fails when they are not down by the barrier timeout, and a failed crossing stays failed [config ONBOARD LONG_WARNING TWO_TRAINS GNSS GNSS_CLOCK]
ltl REQ_LC_006_controller { [] !v_ctrl }
// @property REQ_LC_015_no_braking REQ-LC-015 : with a working crossing and reports within the confirmation age, the protection pattern never takes away a speed the train could otherwise choose (it never makes the train brake or hold back) [config HEALTHY]
ltl REQ_LC_015_no_braking { [] !v_brake }
// @property REQ_LC_009_departure REQ-LC-009 REQ-LC-013 : GNSS: the train (which leaves on the departure signal) leaves the station only at or after the planned departure time, once the centre has received both controllers' acknowledgements of a start time of the departure no later than its initial value (and both have stored one) and no clock fault is known [config GNSS GNSS_CLOCK]
ltl REQ_LC_009_departure { [] !v_dep }
// @property REQ_LC_008_start REQ-LC-008 REQ-LC-010 REQ-LC-011 REQ-LC-014 : GNSS: from the departure signal on, every crossing the train has not passed is warning or holds a start time at least MODEL_WARN_TICKS before the train's earliest arrival from its current state, whatever telegrams are lost or late (initial times, earlier and later updates, lost updates) [config GNSS GNSS_CLOCK]
ltl REQ_LC_008_start { [] !v_start }
// @property REQ_LC_013_clock REQ-LC-013 : GNSS: a controller whose clock is faulty (a fault, or an outage longer than the holdover) is warning from that cycle on [config GNSS_CLOCK]
ltl REQ_LC_013_clock { [] !v_clock }
// @property REQ_LC_010_later REQ-LC-010 : GNSS: once a controller's warning has started (or its departure is active), the start time in force never moves later [config GNSS GNSS_CLOCK]
ltl REQ_LC_010_later { [] !v_later }

// ---- mutants: one per seeded C++ fault (same meaning), then further ones -------------------------
// @mutant MUTANT_CLEAR_WITHOUT_WARNING_TIME violates REQ_LC_003_occupancy : the clearance ignores ws + W <= now + ETA (C++ FAULT_LC_CLEAR_WITHOUT_WARNING_TIME) [config LONG_WARNING]
// @mutant MUTANT_WITHDRAW_AT_FRONT violates REQ_LC_007_end : the withdrawal is sent once the front (not the rear) passed the far edge (C++ FAULT_LC_WITHDRAW_AT_FRONT) [config ONBOARD]
// @mutant MUTANT_STALE_CONFIRMATION violates REQ_LC_003_fresh : the age of a CLOSED confirmation is not checked (C++ FAULT_LC_STALE_CONFIRMATION) [config ONBOARD]
// @mutant MUTANT_END_WITH_REQUESTER violates REQ_LC_007_end : a withdrawal removes every requester, so the warning ends when one of two requesters withdrew (C++ FAULT_LC_END_WITH_REQUESTER) [config TWO_TRAINS]
// @mutant MUTANT_DEPART_WITHOUT_ALL_ACKS violates REQ_LC_009_departure : the departure signal is cleared with one acknowledgement missing (C++ FAULT_LC_DEPART_WITHOUT_ALL_ACKS) [config GNSS]
// @mutant MUTANT_LATER_UPDATE_WHILE_WARNING violates REQ_LC_010_later : a later start time is stored although the warning for the departure has started (C++ FAULT_LC_LATER_UPDATE_WHILE_WARNING) [config GNSS]
// @mutant MUTANT_CLEAR_ON_ANY_CLOSED violates REQ_LC_003_occupancy : a CLOSED report clears the train although it does not list the train among the requesters (a crossing closed for another train; the earlier rule of design §3; C++ FAULT_LC_CLEAR_ON_ANY_CLOSED) [config TWO_TRAINS]
// @mutant MUTANT_REQUEST_LATE violates REQ_LC_002_request : the request only half a tick after the ETA reached W + LEAD [config ONBOARD]
// @mutant MUTANT_NO_DWELL violates REQ_LC_002_request : the ETA of a train standing in its dwell ignores the remaining dwell (request too early) [config ONBOARD]
// @mutant MUTANT_NO_PROTECTION_REQUESTED violates REQ_LC_003_occupancy : a REQUESTED crossing gives no protection limit [config ONBOARD]
// @mutant MUTANT_LOWER_LATE violates REQ_LC_006_controller : the barriers are commanded down one tick late [config ONBOARD]
// @mutant MUTANT_CLOSED_WITHOUT_DOWN violates REQ_LC_006_controller : the barrier timeout gives CLOSED instead of FAILED [config ONBOARD]
// @mutant MUTANT_UPDATE_FROM_REST violates REQ_LC_008_start : the centre recomputes the start time of a running train from rest, ignoring the reported speed bound (a later time) [config GNSS]
// @mutant MUTANT_STOP_AT_FRONT violates REQ_LC_007_end : the centre sends the warning stop once the reported front passed the crossing [config GNSS]
// @mutant MUTANT_DEPART_BEFORE_TDEP violates REQ_LC_009_departure : the departure signal does not wait for the planned departure time [config GNSS]
// @mutant MUTANT_CLOCK_FAULT_IGNORED violates REQ_LC_013_clock : a faulty clock does not start the warning [config GNSS_CLOCK]

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
// GNSS, per crossing: A = 60..72, B = 75..87 (same meaning)
// @goal 60 REQ-LC-011 : boundary: A starts its warning on its own exactly at the stored start time [config GNSS]
// @goal 61 REQ-LC-011 REQ-LC-014 : A starts its warning on its own in a cycle without any centre telegram [config GNSS]
// @goal 62 REQ-LC-012 : A's warning stop received: its departure removed [config GNSS]
// @goal 63 REQ-LC-012 REQ-LC-007 : A's warning ends after the warning stop (CLOSED to OPENING) [config GNSS]
// @goal 64 REQ-LC-006 REQ-LC-014 : A's barrier stuck up: FAILED, the lights keep warning [config GNSS]
// @goal 65 REQ-LC-010 : an earlier start time stored at A [config GNSS]
// @goal 66 REQ-LC-010 : a later start time stored at A before its warning started [config GNSS]
// @goal 67 REQ-LC-010 : a later start time refused at A (its warning started): the earlier stays in force [config GNSS]
// @goal 68 REQ-LC-013 : boundary: A's GNSS outage exactly the holdover: still not faulty [config GNSS_CLOCK]
// @goal 69 REQ-LC-013 : A's outage beyond the holdover: clock faulty, warning at once [config GNSS_CLOCK]
// @goal 70 REQ-LC-013 : A's clock reports a fault: faulty, warning at once [config GNSS_CLOCK]
// @goal 71 REQ-LC-013 : A's GNSS back during the holdover: synchronised again [config GNSS_CLOCK]
// @goal 72 REQ-LC-008 REQ-LC-011 : boundary: the train arrives at A exactly W after its warning started [config GNSS]
// @goal 75 REQ-LC-011 : boundary: B starts its warning on its own exactly at the stored start time [config GNSS]
// @goal 76 REQ-LC-011 REQ-LC-014 : B starts its warning on its own in a cycle without any centre telegram [config GNSS]
// @goal 77 REQ-LC-012 : B's warning stop received: its departure removed [config GNSS]
// @goal 78 REQ-LC-012 REQ-LC-007 : B's warning ends after the warning stop (CLOSED to OPENING) [config GNSS]
// @goal 79 REQ-LC-006 REQ-LC-014 : B's barrier stuck up: FAILED, the lights keep warning [config GNSS]
// @goal 80 REQ-LC-010 : an earlier start time stored at B [config GNSS]
// @goal 81 REQ-LC-010 : a later start time stored at B before its warning started [config GNSS]
// @goal 82 REQ-LC-010 : a later start time refused at B (its warning started): the earlier stays in force [config GNSS]
// @goal 83 REQ-LC-013 : boundary: B's GNSS outage exactly the holdover: still not faulty [config GNSS_CLOCK]
// @goal 84 REQ-LC-013 : B's outage beyond the holdover: clock faulty, warning at once [config GNSS_CLOCK]
// @goal 85 REQ-LC-013 : B's clock reports a fault: faulty, warning at once [config GNSS_CLOCK]
// @goal 86 REQ-LC-013 : B's GNSS back during the holdover: synchronised again [config GNSS_CLOCK]
// @goal 87 REQ-LC-008 REQ-LC-011 : boundary: the train arrives at B exactly W after its warning started [config GNSS]
// GNSS, centre and train
// @goal 90 REQ-LC-009 : the departure signal cleared (every start time acknowledged, t_dep reached) [config GNSS]
// @goal 91 REQ-LC-009 REQ-LC-014 : the departure signal held at or after t_dep: an acknowledgement missing [config GNSS]
// @goal 92 REQ-LC-009 REQ-LC-013 : the departure signal held by a reported clock fault [config GNSS_CLOCK]
// @goal 93 REQ-LC-012 : A's passage reported: warning stop pending [config GNSS]
// @goal 94 REQ-LC-012 REQ-LC-014 : the rear passed A but no passage report arrived: the warning continues [config GNSS]
// @goal 95 REQ-LC-010 REQ-LC-014 : a later update of B lost: B keeps the earlier start time in force (the centre's is later) [config GNSS]
// @goal 96 REQ-LC-010 : a start time recomputed from a late position report (taken a tick before) [config GNSS]
// @goal 97 REQ-LC-010 : a later start time of B computed from a train still standing at the station after t_dep [config GNSS]
// @goal 98 REQ-LC-009 : an acknowledgement arriving a tick late [config GNSS]
// @goal 99 REQ-LC-006 : both crossings warning at once (GNSS) [config GNSS]
// @goal 100 REQ-LC-009 : boundary: the train departs exactly at t_dep [config GNSS]

#ifdef TRAPS
#include "lc_goals.pml"
#endif
