"""The planted bugs, selectable with --bug NAME (repeatable). Each breaks exactly one rule of
protocol-facts.md; README.md explains which telegram shows it."""

BUGS = {
    "fcb_reexecute":
        "§C.6 responder: a repeat (FCV=1, same FCB as the same SA's previous action frame) "
        "is executed again instead of resending the stored reply",
    "fcb_global":
        "§C.6 responder: 'FCB is stored per source address' - one FCB memory is shared by all "
        "requesting stations",
    "diag_always1_wait_prm":
        "§D.4 Station_Status_2 bit 2 'always 1' is 0 in Wait_Prm (05 -> 01)",
    "get_cfg_saps_unswapped":
        "§B.2 'a response mirrors the request' - the Get_Cfg reply carries DSAP 59 / SSAP 62 "
        "(the request's order) instead of DSAP 62 / SSAP 59",
    "lock_ignored":
        "§D.8 Locking - a Set_Prm from another master is accepted while the slave is locked",
    "group_ignored":
        "§D.6 Group_Select - Global_Control is applied although Group_Select & Group_Ident = 0",
}
