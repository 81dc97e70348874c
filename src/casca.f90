program casca
  implicit none
  print '(a)', 'casca 0.1.0'
end program casca
