/*
 * railproof — level-crossing protection: what the two level-crossing models share
 * (spec/design/lc.md §6): the configuration symbols, the model bounds, the state, the
 * crossing controller, the train's motion, the earliest arrival and the per-crossing checks.
 * Included by models/lc.pml (the on-board-requested warning, D5 §5.3) and by
 * models/lc_gnss.pml (GNSS-time pre-armed crossings, D4 §4.8.2), which defines GNSS before
 * it includes this file: the #ifdef GNSS that remain below are the two configurations of
 * these shared parts (the controller triggered by requests or by stored start times). Not a
 * model of its own.
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

