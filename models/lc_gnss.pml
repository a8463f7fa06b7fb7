/*
 * railproof — level-crossing protection, the GNSS-time pre-armed crossings of low-cost lines
 * (D4 §4.8.2; spec/design/lc.md §5, §6). C++: lc::wayside::CentreScheduler::Cycle
 * (cpp/runtime/lc/src/wayside/centre_scheduler.cpp), lc::wayside::CrossingController::Cycle
 * (cpp/runtime/lc/src/wayside/crossing_controller.cpp). The line, the train, its motion, the
 * controllers and the checks are those of models/lc.pml (the on-board-requested warning; its
 * header describes them), shared through models/include/lc_shared.pml.
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
 * Configurations (-D; each property names those it is verified in): GNSS (= default: losses,
 * delays, barrier faults); GNSS_CLOCK (GNSS outages, holdover and clock faults, losses,
 * working barriers); GNSS_FAIR (GNSS with a fair radio and working barriers: the bounded
 * response of the warning's end); WALK stops after MODEL_CYCLES ticks or at the horizon
 * (random walks); TRAPS adds the goal flags.
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

#define GNSS
#include "lc_shared.pml"

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


// @property REQ_LC_003_occupancy REQ-LC-003 REQ-LC-006 REQ-LC-011 REQ-LC-014 : the train never occupies a crossing (front at or beyond the near edge, rear before the far edge, also inside a tick) unless it has warned for at least MODEL_WARN_TICKS at the train's arrival and is CLOSED; ONBOARD: or its barriers lost their down detection while the train was cleared (a detected failure under a cleared train); GNSS: or it FAILED (no train-side protection: the lights keep warning) [config GNSS GNSS_CLOCK]
ltl REQ_LC_003_occupancy { [] !v_occ }
// @property REQ_LC_007_end REQ-LC-004 REQ-LC-007 REQ-LC-012 : a withdrawal (ONBOARD) or warning stop (GNSS) is sent only after the train's rear has passed the crossing's far edge, and a warning ends (CLOSED to OPENING) only when no requester is left and the train that needed it has passed with its rear [config GNSS GNSS_CLOCK]
ltl REQ_LC_007_end { [] !v_end }
// @property REQ_LC_007_ends REQ-LC-007 REQ-LC-004 REQ-LC-012 : with a working crossing and a fair radio (no link loses two telegrams in a row) the warning of a crossing ends (OPEN) at most MODEL_RESPONSE_TICKS ticks after the train's rear passed it (bounded response: the liveness of design §6 under weak fairness, as a safety property) [config GNSS_FAIR]
ltl REQ_LC_007_ends { [] !v_live }
// @property REQ_LC_006_controller REQ-LC-006 : a controller starts the warning in the cycle a request arrives (GNSS: its stored start time is reached or its clock is faulty), commands the barriers down MODEL_LOWER_TICKS later, is CLOSED only while the barriers are detected down, fails when they are not down by the barrier timeout, and a failed crossing stays failed [config GNSS GNSS_CLOCK]
ltl REQ_LC_006_controller { [] !v_ctrl }
// @property REQ_LC_009_departure REQ-LC-009 REQ-LC-013 : GNSS: the train (which leaves on the departure signal) leaves the station only at or after the planned departure time, once the centre has received both controllers' acknowledgements of a start time of the departure no later than its initial value (and both have stored one) and no clock fault is known [config GNSS GNSS_CLOCK]
ltl REQ_LC_009_departure { [] !v_dep }
// @property REQ_LC_008_start REQ-LC-008 REQ-LC-010 REQ-LC-011 REQ-LC-014 : GNSS: from the departure signal on, every crossing the train has not passed is warning or holds a start time at least MODEL_WARN_TICKS before the train's earliest arrival from its current state, whatever telegrams are lost or late (initial times, earlier and later updates, lost updates) [config GNSS GNSS_CLOCK]
ltl REQ_LC_008_start { [] !v_start }
// @property REQ_LC_013_clock REQ-LC-013 : GNSS: a controller whose clock is faulty (a fault, or an outage longer than the holdover) is warning from that cycle on [config GNSS_CLOCK]
ltl REQ_LC_013_clock { [] !v_clock }
// @property REQ_LC_010_later REQ-LC-010 : GNSS: once a controller's warning has started (or its departure is active), the start time in force never moves later [config GNSS GNSS_CLOCK]
ltl REQ_LC_010_later { [] !v_later }

// ---- mutants: one per seeded C++ fault (same meaning), then further ones -------------------------
// @mutant MUTANT_DEPART_WITHOUT_ALL_ACKS violates REQ_LC_009_departure : the departure signal is cleared with one acknowledgement missing (C++ FAULT_LC_DEPART_WITHOUT_ALL_ACKS) [config GNSS]
// @mutant MUTANT_LATER_UPDATE_WHILE_WARNING violates REQ_LC_010_later : a later start time is stored although the warning for the departure has started (C++ FAULT_LC_LATER_UPDATE_WHILE_WARNING) [config GNSS]
// @mutant MUTANT_UPDATE_FROM_REST violates REQ_LC_008_start : the centre recomputes the start time of a running train from rest, ignoring the reported speed bound (a later time) [config GNSS]
// @mutant MUTANT_STOP_AT_FRONT violates REQ_LC_007_end : the centre sends the warning stop once the reported front passed the crossing [config GNSS]
// @mutant MUTANT_DEPART_BEFORE_TDEP violates REQ_LC_009_departure : the departure signal does not wait for the planned departure time [config GNSS]
// @mutant MUTANT_CLOCK_FAULT_IGNORED violates REQ_LC_013_clock : a faulty clock does not start the warning [config GNSS_CLOCK]

// ---- coverage goals (trap properties) -------------------------------------------------------------
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
#include "lc_gnss_goals.pml"
#endif
