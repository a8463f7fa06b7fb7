railproof_runtime_module(onboard_unit SIDE onboard LINKS tg mb_onboard br ra lc_onboard messages)
