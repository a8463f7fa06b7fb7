railproof_runtime_module(wayside_unit SIDE wayside LINKS tg mb_wayside lc_wayside messages)
