/PROG  PROCESS_CELL_FRAMES
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "robomax frames";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 29;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
   1:  !robomax_py 0.1.0, ;
   2:  !+ cell process_cell, ;
   3:  !+ cell file sha256 ;
   4:  !+ 88859a5ee20f1866af51228139925b ;
   5:  !+98ff8d83876345bd50c8fce2a9b032b ;
   6:  !+924, planned cycle 5.462 s ;
   7:  !robot kr125, tool spot_gun_c, ;
   8:  !+ axes joint_a1 joint_a2 ;
   9:  !+ joint_a3 joint_a4 joint_a5 ;
  10:  !+ joint_a6 ;
  11:  !frames of PROCESS_CELL ;
  12:  PR[40]=LPOS    ;
  13:  PR[40]=PR[40]-PR[40]    ;
  14:  PR[40,1]=200.000    ;
  15:  PR[40,2]=0.000    ;
  16:  PR[40,3]=270.000    ;
  17:  PR[40,4]=-90.0000    ;
  18:  PR[40,5]=0.0000    ;
  19:  PR[40,6]=-90.0000    ;
  20:  UTOOL[2]=PR[40] ;
  21:  PR[41]=LPOS    ;
  22:  PR[41]=PR[41]-PR[41]    ;
  23:  PR[41,1]=1800.000    ;
  24:  PR[41,2]=0.000    ;
  25:  PR[41,3]=710.000    ;
  26:  PR[41,4]=0.0000    ;
  27:  PR[41,5]=0.0000    ;
  28:  PR[41,6]=0.0000    ;
  29:  UFRAME[3]=PR[41] ;
/POS
/END
